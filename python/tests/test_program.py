"""Standalone programs on a Module (load, run, step, breakpoints,
registers, trace) and the assembler/disassembler."""

import sys

import pytest

import tmclsim
from tmclsim import AssemblyError, Instruction, Program, TmclError

COUNTER = """
// Count in the accumulator, store every 10th value in user variable 5.
Start:
    CALC LOAD, 0
Loop:
    CALC ADD, 1
    COMP 10
    JC LT, Loop
    AGP 5, 2
    JA Start
"""

MOVER = """
#include Parameters.inc
    SAP 4, 0, 2047
Back:
    MVP ABS, 0, 100000
    WAIT POS, 0, 0
    MVP ABS, 0, 0
    WAIT POS, 0, 0
    JA Back
"""


def test_load_run_stop(module):
    program = module.load_program(COUNTER)
    assert program.symbols == {"Start": 0, "Loop": 1}
    assert module.program_mode == "reset" and module.pc == 0  # 131 after loading
    module.run()
    module.advance(0.01)
    assert module.program_mode == "run"
    assert module.get_global_parameter(5, 2) == 10
    assert module.instructions_executed in (400, 401)  # 25 µs each
    module.stop()
    assert module.program_mode == "stop"
    module.run("Loop")
    assert module.program_mode == "run"


def test_programs_from_every_form(module, tmp_path):
    assembled = tmclsim.assemble(COUNTER)
    for form in [assembled, assembled.to_binary(), list(assembled.instructions), [tuple(i) for i in assembled]]:
        loaded = module.load_program(form)
        assert loaded.instructions == assembled.instructions
    source = tmp_path / "counter.tmc"
    source.write_text(COUNTER)
    assert module.load_program(source).symbols == assembled.symbols
    assert module.send(134, 0, 0, 1).instruction == Instruction.parse("CALC ADD, 1")


def test_a_program_too_big_for_the_module(module):
    with pytest.raises(TmclError) as e:
        module.load_program(["CALC ADD, 1"] * 1025)
    assert e.value.status == 4 and "1024" in str(e.value)


def test_step_breakpoints_and_registers(module):
    module.load_program(COUNTER)
    assert module.step() and module.pc == 1
    assert module.step() and module.registers.accumulator == 1
    module.step()  # COMP 10
    assert module.registers.compare == "less"
    module.breakpoints = ["Start", 5]
    assert module.breakpoints == [0, 5]
    module.run()
    module.advance(1)
    assert module.hit_breakpoint == 5 and module.program_mode == "step"
    assert module.registers.accumulator == 10
    module.run()
    module.advance(1)
    assert module.hit_breakpoint == 0
    with pytest.raises(ValueError, match="not a label"):
        module.breakpoints = ["Nowhere"]
    module.breakpoints = []
    module.run()
    module.advance(0.001)
    module.pause()
    assert module.program_mode == "step"
    assert module.registers.error_flags == []


def test_wait_in_a_program_steps_through_time(module):
    module.load_program(MOVER)
    module.breakpoints = [3]  # the second MVP, after the first WAIT POS
    module.run()
    module.advance(60)
    assert module.hit_breakpoint == 3
    assert module.actual_position() == 100000
    module.breakpoints = []
    assert module.step()  # MVP ABS, 0, 0
    assert module.step()  # WAIT POS starts waiting
    assert module.waiting
    assert module.step(timeout=30)  # the wait ends with the move, then JA
    assert module.actual_position() == 0 and module.pc == 1


def test_trace_as_lists_without_numpy(module, monkeypatch):
    monkeypatch.setitem(sys.modules, "numpy", None)
    module.load_program(MOVER)
    module.tracing = True
    module.run()
    module.advance(0.5)
    trace = module.take_trace()
    assert all(isinstance(column, list) for column in trace.values())
    lengths = {len(column) for column in trace.values()}
    assert len(lengths) == 1 and lengths.pop() > 0
    assert trace["opcode"][:2] == [5, 4]  # SAP, MVP
    assert trace["time"][1] == pytest.approx(25e-6)
    assert set(trace) >= {"time", "pc", "opcode", "type", "motor", "value", "accumulator", "x", "failed", "position_0", "speed_0"}
    assert module.take_trace()["pc"] == []


def test_trace_as_numpy_arrays(module):
    np = pytest.importorskip("numpy")
    module.load_program(COUNTER)
    module.tracing = True
    module.run()
    module.advance(0.25)
    trace = module.take_trace()
    assert all(isinstance(column, np.ndarray) for column in trace.values())
    assert len(trace["pc"]) == 10000 and trace["pc"].dtype == np.int64
    assert np.all(np.diff(trace["time"]) > 0)
    assert trace["accumulator"].max() == 10
    module.tracing = False
    assert not module.tracing


def test_failed_commands_show_in_the_trace(module):
    # The assembler checks the range; instructions go in unchecked.
    module.load_program([Instruction.parse("SAP 4, 0, 99999"), "STOP"])
    module.tracing = True
    module.run()
    module.advance(0.001)
    trace = module.take_trace()
    assert list(trace["failed"][:1]) == [4]


def test_assemble_disassemble_round_trip():
    program = tmclsim.assemble(MOVER, file_name="mover.tmc")
    # Six instructions and the STOP appended after JA (docs/behaviour.md rule 93).
    assert len(program) == 7 and program[-2] == Instruction.parse("JA 1")
    assert program[-1] == Instruction.parse("STOP") and program.to_binary()[-8:] == bytes.fromhex("1C000000000000 1C")
    source = program.disassemble()
    assert "Back:" in source
    again = tmclsim.assemble(source)
    assert again.to_binary() == program.to_binary()
    assert tmclsim.disassemble(program.to_binary(), program.symbol_file()) == source
    assert tmclsim.disassemble(program) == source
    back = Program.from_binary(program.to_binary(), program.symbols)
    assert back == program or back.instructions == program.instructions
    assert "MAXIMUM_SPEED" in program.constants or program.constants
    # Labels first, then the source map (crates/asm/README.md, "Symbol file").
    symbols = program.symbol_file().splitlines()
    assert symbols[0] == "Back 1"
    assert symbols[1].startswith("// source map")
    assert symbols[-1] == "@5\tmover.tmc\t9\t5\tJA Back"


def test_raw_words_survive_disassembly():
    words = [Instruction(4, 0, 0, 100), Instruction(24, 0, 0, 7), Instruction(200, 1, 2, 3)]
    text = tmclsim.disassemble(words)
    assert "#db 24, 0, 0, 7" in text
    # The words do not end in STOP: the assembler appends one (rule 93).
    assert tmclsim.assemble(text, profile=None).instructions == words + [Instruction.parse("STOP")]


def test_assembly_errors_carry_diagnostics():
    with pytest.raises(AssemblyError) as e:
        tmclsim.assemble("Loop:\n    MVP ABS, 5, 100\n    JA Lop\n", file_name="bad.tmc")
    diagnostics = e.value.diagnostics
    assert [(d.file, d.line, d.column) for d in diagnostics] == [("bad.tmc", 2, 14), ("bad.tmc", 3, 8)]
    assert "did you mean 'Loop'" in diagnostics[1].message
    assert str(e.value).splitlines()[1] == "bad.tmc:3:8: error: unknown label 'Lop' (did you mean 'Loop'?)"
    # Without a profile, motor 5 is fine.
    with pytest.raises(AssemblyError) as e:
        tmclsim.assemble("JA Nowhere\n", profile=None)
    assert len(e.value.diagnostics) == 1


def test_includes(tmp_path):
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "speeds.inc").write_text("FAST = 2000\n")
    main = tmp_path / "main.tmc"
    main.write_text("#include speeds.inc\n    SAP 4, 0, FAST\n")
    with pytest.raises(AssemblyError, match="cannot find include file"):
        tmclsim.assemble_file(main)
    program = tmclsim.assemble_file(main, include_path=[tmp_path / "lib"])
    assert program.instructions == [Instruction.parse("SAP 4, 0, 2000"), Instruction.parse("STOP")]
    assert program.constants["FAST"] == 2000
    # The source map names the line each instruction comes from; the
    # appended STOP comes from none.
    assert program.source_map == [(str(main), 2, 5, "SAP 4, 0, FAST")]
    assert program.appended_stop
    assert tmclsim.Program.from_binary(program.to_binary()).source_map == []
    assert not tmclsim.Program.from_binary(program.to_binary()).appended_stop


def test_instructions():
    i = Instruction(4, 0, 0, -10000)
    assert (i.opcode, i.type, i.motor, i.value) == (4, 0, 0, -10000)
    assert i.mnemonic == "MVP ABS, 0, -10000" == str(i)
    assert eval(repr(i), {"Instruction": Instruction}) == i
    assert i.to_bytes() == bytes([4, 0, 0, 0xFF, 0xFF, 0xD8, 0xF0])
    assert i.frame(1) == bytes([0x01, 0x04, 0x00, 0x00, 0xFF, 0xFF, 0xD8, 0xF0, 0xCB])
    assert Instruction(4, 0, 0, 0xFFFFFFFF).value == -1
    assert len({i, Instruction.parse("MVP ABS, 0, -10000")}) == 1
    with pytest.raises(ValueError):
        Instruction(4, 0, 0, 2**33)
    with pytest.raises(ValueError, match="column"):
        Instruction.parse("MVP UP, 0, 1")


def test_a_program_goes_on_through_one_long_advance(module):
    # One call of a minute: the program keeps moving back and forth, exactly
    # as in many short calls.
    module.load_program(MOVER)
    module.run()
    module.advance(60)
    one_call = module.instructions_executed
    other = tmclsim.Module()
    other.load_program(MOVER)
    other.run()
    for _ in range(600):
        other.advance(0.1)
    assert one_call > 20
    assert one_call == other.instructions_executed


def test_reference_search_from_far_below_the_home_switch():
    module = tmclsim.Module(world="[[axis]]\nstart = -500000\n")
    module.set_axis_parameter("Reference search mode", 0, 8)
    module.send("RFS START, 0")
    module.advance(240)  # 600 000 µsteps at the search speed take about 200 s
    assert module.send("RFS STATUS, 0").value == 1
    module.advance(60)
    assert module.send("RFS STATUS, 0").value == 0
    assert module.get_axis_parameter("Last reference position") == 605000
