"""An EEPROM file has one user at a time, a write it does not take is not
acknowledged as stored, a file holding what the module never stores is
refused, a read-only file is never replaced, and a file that cannot be
read says why (docs/robustness.md, "Crash-safe EEPROM")."""

import gc
import json
import os
import stat

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


def test_a_file_with_a_value_the_module_never_stores_is_refused(tmp_path):
    # docs/behaviour.md rule 88: GP 75 = 2^31 - 1 would hold every reply
    # back for 24 days.
    path = tmp_path / "m.eeprom"
    text = json.dumps({"format": 1, "module": "TMCM-1141", "axis": {"0/4": -2147483648},
                       "global": {"0/75": 2147483647}, "coordinates": {}})
    path.write_text(text)
    with pytest.raises(ValueError) as refused:
        tmclsim.Module(eeprom=path)
    message = str(refused.value)
    assert message.startswith(f"{path}: refused: entries a TMCM-1141 never stores")
    assert 'axis "0/4" = -2147483648: AP 4 (Maximum positioning speed) of motor 0 takes 1…2047' in message
    assert 'global "0/75" = 2147483647: GP 75 (Telegram pause time) of bank 0 takes 0…255' in message
    assert path.read_text() == text
    # Nor can an address GP 66 does not take get into a file.
    with pytest.raises(ValueError, match="address 0: a TMCM-1141 takes 1…255"):
        tmclsim.Module(eeprom=tmp_path / "other.eeprom", address=0)
    assert not (tmp_path / "other.eeprom").exists()


def test_a_read_only_file_is_used_and_never_replaced(tmp_path):
    # docs/behaviour.md rule 89.
    path = tmp_path / "m.eeprom"
    module = tmclsim.Module(eeprom=path)
    module.set_axis_parameter(4, 0, 1500)
    assert module.send("STAP 4, 0").status == 100
    del module
    gc.collect()
    path.chmod(0o444)
    before = (path.read_bytes(), path.stat().st_ino)
    with pytest.warns(UserWarning, match=r"read-only \(mode 0444.*answered with status 5"):
        module = tmclsim.Module(eeprom=path, address=3)
    assert module.address == 3
    assert module.get_axis_parameter(4) == 1500
    module.set_axis_parameter(4, 0, 2000)
    assert module.send("STAP 4, 0").status == 5
    with pytest.raises(OSError, match="read-only"):
        module.eeprom_save(path)
    assert (path.read_bytes(), path.stat().st_ino) == before
    assert stat.S_IMODE(path.stat().st_mode) == 0o444


def test_a_file_that_cannot_be_read_raises_oserror_with_the_reason(tmp_path):
    # Only a missing file means factory defaults (rule 89).
    plain = tmp_path / "plain"
    plain.write_text("a file")
    path = plain / "m.eeprom"
    with pytest.raises(OSError, match=f"{path}: cannot read the EEPROM file: Not a directory"):
        tmclsim.Module(eeprom=path)
