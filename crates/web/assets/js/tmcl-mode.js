// TMCL-IDE source highlighting for CodeMirror 5 (simple mode): mnemonics,
// symbolic operands, numbers, labels, comments and directives.
const MNEMONICS = "ROR|ROL|MST|MVP|SAP|GAP|STAP|RSAP|SGP|GGP|STGP|RSGP|RFS|SIO|GIO|SCO|GCO|CCO|CALC|COMP|JC|JA|CSUB|RSUB|EI|DI|WAIT|STOP|SAC|SCV|GCV|CALCX|AAP|AGP|CLE|VECT|RETI|ACO|CALCVV|CALCVA|CALCAV|CALCVX|CALCXV|CALCV|RST|DJNZ|CALL|MVPA|MVPXA|UF[0-7]";
const OPERANDS = "ABS|REL|COORD|START|STOP|STATUS|ADD|SUB|MUL|DIV|MOD|AND|OR|XOR|NOT|LOAD|SWAP|ZE|NZ|EQ|NE|GT|GE|LT|LE|ETO|EAL|EDV|EPO|ESD|TICKS|POS|REFSW|LIMSW|RFS|ALL|TIMER|VAR|ACC|X";

CodeMirror.defineSimpleMode("tmcl", {
  start: [
    { regex: /\/\/.*/, token: "comment" },
    { regex: /\/\*/, token: "comment", next: "comment" },
    { regex: /#\s*(include|db)\b.*|#\d.*/i, token: "meta" },
    { regex: /[A-Za-z_][A-Za-z0-9_]*\s*:/, token: "def", sol: true },
    { regex: new RegExp(`\\b(?:${MNEMONICS})\\b`, "i"), token: "keyword" },
    { regex: new RegExp(`\\b(?:${OPERANDS})\\b`, "i"), token: "atom" },
    { regex: /(?:\$|0x)[0-9a-f]+|0b[01]+|-?\d+/i, token: "number" },
    { regex: /[A-Za-z_][A-Za-z0-9_]*/, token: "variable-2" },
  ],
  comment: [
    { regex: /.*?\*\//, token: "comment", next: "start" },
    { regex: /.*/, token: "comment" },
  ],
  meta: { lineComment: "//" },
});
