"""An EEPROM file has one user at a time, and a write it does not take is
not acknowledged as stored (docs/robustness.md, "Crash-safe EEPROM")."""

import gc
import os

import pytest

import tmclsim


def test_a_second_module_on_the_same_file_is_refused(tmp_path):
    path = tmp_path / "m.eeprom"
    first = tmclsim.Module(eeprom=path)
    first.set_axis_parameter(4, 0, 1500)
    assert first.send("STAP 4, 0").status == 100
    with pytest.raises(OSError) as refused:
        tmclsim.Module(eeprom=path)
    text = str(refused.value)
    assert text.startswith(f"{path}: ") and f"in use by another tmclsim (pid {os.getpid()})" in text
    # Through a symbolic link it is the same file.
    link = tmp_path / "link.eeprom"
    link.symlink_to(path)
    with pytest.raises(OSError, match="in use by another tmclsim"):
        tmclsim.Module(eeprom=link)
    # Nor does eeprom_save write over a file another module keeps.
    with pytest.raises(OSError, match="in use by another tmclsim"):
        tmclsim.Module().eeprom_save(path)
    # The holder is unharmed, and its file is free once it is gone.
    assert first.send("GAP 4, 0").value == 1500
    del first
    gc.collect()
    again = tmclsim.Module(eeprom=link)
    assert again.get_axis_parameter(4) == 1500
    assert link.is_symlink()


def test_a_write_the_file_does_not_take_is_answered_with_status_5(tmp_path, capfd):
    store = tmp_path / "store"
    store.mkdir()
    path = store / "m.eeprom"
    module = tmclsim.Module(eeprom=path)
    module.set_axis_parameter(4, 0, 1000)
    assert module.send("STAP 4, 0").status == 100
    # No file can be created where the directory was.
    away = tmp_path / "away"
    store.rename(away)
    store.write_text("")
    module.set_axis_parameter(4, 0, 2000)
    assert module.send("STAP 4, 0").status == 5
    assert f"cannot write EEPROM file {path}" in capfd.readouterr().err
    assert module.send("GAP 4, 0").value == 2000
    assert module.send("RSAP 4, 0").status == 100
    assert module.get_axis_parameter(4) == 1000
    store.unlink()
    away.rename(store)
    module.set_axis_parameter(4, 0, 2000)
    assert module.send("STAP 4, 0").status == 100
    del module
    gc.collect()
    assert tmclsim.Module(eeprom=path).get_axis_parameter(4) == 2000
