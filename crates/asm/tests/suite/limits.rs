//! The assembler's limits: long lines, huge sources and floods of errors
//! get a clear answer in bounded memory (docs/robustness.md). Endless
//! source files are refused where files are read
//! (crates/server/tests/suite/sources.rs).

use tmclsim_asm::limits::{MAX_ERRORS, MAX_LINE_BYTES, MAX_TOTAL_SOURCE_BYTES};
use tmclsim_asm::{MemoryResolver, NoIncludes, assemble};

#[test]
fn a_line_past_the_limit_is_an_error_and_the_rest_is_still_checked() {
    let long = format!("  SAP 4, 0, {}", "1".repeat(MAX_LINE_BYTES));
    let source = format!("ROR 0, 100\n{long}\nMVPP ABS, 0, 10\nSTOP\n");
    let d = assemble(&source, "long.tmc", &NoIncludes, None).unwrap_err();
    assert_eq!(d.len(), 2, "{d:?}");
    assert_eq!((d[0].line, d[0].column), (2, 1));
    assert_eq!(d[0].message, format!("line longer than {MAX_LINE_BYTES} bytes"));
    assert_eq!(d[1].line, 3, "the line after it is still parsed: {}", d[1]);
    // A line of exactly the limit is parsed as usual.
    let fits = format!("STOP{}\n", " ".repeat(MAX_LINE_BYTES - 4));
    assert!(assemble(&fits, "fits.tmc", &NoIncludes, None).is_ok());
}

#[test]
fn a_flood_of_errors_shows_the_first_ones_and_counts_the_rest() {
    let source = "bogus!\n".repeat(100_000);
    let d = assemble(&source, "flood.tmc", &NoIncludes, None).unwrap_err();
    assert_eq!(d.len(), MAX_ERRORS + 1);
    let lines: Vec<usize> = d[..MAX_ERRORS].iter().map(|d| d.line).collect();
    assert_eq!(lines, (1..=MAX_ERRORS).collect::<Vec<_>>(), "the first errors, in source order");
    let last = d.last().unwrap();
    assert_eq!(last.line, 0);
    assert_eq!(last.message, format!("{} more errors not shown (the first {MAX_ERRORS} are)", 100_000 - MAX_ERRORS));
}

#[test]
fn the_kept_errors_are_the_earliest_even_when_found_late() {
    // Pass 2 finds the unknown label on line 1 after pass 1 has reported
    // every bad line further down.
    let source = format!("JA Nowhere\n{}", "bogus!\n".repeat(2 * MAX_ERRORS));
    let d = assemble(&source, "late.tmc", &NoIncludes, None).unwrap_err();
    assert_eq!(d[0].line, 1, "{}", d[0]);
    assert!(d[0].message.contains("Nowhere"), "{}", d[0]);
    assert_eq!(d[MAX_ERRORS - 1].line, MAX_ERRORS);
}

#[test]
fn includes_count_towards_one_budget() {
    let chunk = format!("{}\n", "// filler".repeat(100)).repeat(MAX_TOTAL_SOURCE_BYTES / 1001 / 3 + 1);
    let mut files = MemoryResolver::new();
    for n in ["a.inc", "b.inc", "c.inc", "d.inc"] {
        files.files.insert(n.to_string(), chunk.clone());
    }
    let source = "#include \"a.inc\"\n#include \"b.inc\"\n#include \"c.inc\"\n#include \"d.inc\"\nSTOP\n";
    let d = assemble(source, "main.tmc", &files, None).unwrap_err();
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(d[0].message, format!("the sources pass {} MiB, the limit of one assembly", MAX_TOTAL_SOURCE_BYTES >> 20));
    assert!(d[0].file.ends_with("c.inc") || d[0].file.ends_with("d.inc"), "{}", d[0]);
}

#[test]
fn statements_past_the_limit_end_the_assembly_with_one_error() {
    use tmclsim_asm::limits::MAX_STATEMENTS;
    let source = (0..MAX_STATEMENTS + 5).map(|i| format!("L{i}:\n")).collect::<String>();
    let d = assemble(&source, "labels.tmc", &NoIncludes, None).unwrap_err();
    assert_eq!(d.len(), 1, "{:?}", &d[..d.len().min(3)]);
    assert_eq!(d[0].line, MAX_STATEMENTS + 1);
    assert_eq!(d[0].message, format!("more than {MAX_STATEMENTS} statements, the limit of one assembly"));
    let fits = (0..MAX_STATEMENTS).map(|i| format!("L{i}:\n")).collect::<String>();
    assert!(assemble(&fits, "labels.tmc", &NoIncludes, None).is_ok());
}

#[test]
fn suggestions_stop_when_their_work_is_spent() {
    use tmclsim_asm::limits::MAX_SUGGESTION_WORK;
    // Each jump's "did you mean" compares its name with 20 000 labels of
    // about its length; the work allowed pays for the first few searches.
    let jumps: String = (0..30).map(|i| format!("JA Label{i:05}x\n")).collect();
    let labels: String = (0..20_000).map(|i| format!("Label{i:05}: STOP\n")).collect();
    let d = assemble(&format!("{jumps}{labels}"), "many.tmc", &NoIncludes, None).unwrap_err();
    assert_eq!(d.len(), 30, "{:?}", &d[..3]);
    assert_eq!(d[0].message, "unknown label 'Label00000x' (did you mean 'Label00000'?)");
    let suggested = d.iter().take_while(|d| d.message.contains("did you mean")).count();
    assert!((1..30).contains(&suggested), "{suggested} of 30 errors have a suggestion with {MAX_SUGGESTION_WORK} cells of work");
    assert!(d[suggested..].iter().all(|d| !d.message.contains("did you mean")), "none after the work is spent");
    assert_eq!(d[29].message, "unknown label 'Label00029x'");
}
