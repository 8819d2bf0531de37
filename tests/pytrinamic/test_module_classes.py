"""PyTrinamic's module classes end to end, data-driven: for every module
class that names a module tmclsim serves (and the closest class for a
module PyTrinamic has none for), every axis and global parameter its
enums name is read, written within the profile's range and read back, and
its motor and IO API is driven, over the pty and over TCP.

What a parameter allows (access, range) is read from `tmclsim profile`,
the served module's own table; a parameter the class names but the
profile lacks must be refused with status 3 (wrong type), as the module's
manual has no such row (docs/modules.md: AP 141 on the TMCM-1141). A
class that makes more motor objects than the module has axes (PyTrinamic's
TMCM3216 makes six for a three-axis module) is driven on the module's axes;
the others are refused with status 4 (no such motor)."""

import inspect
import re
import subprocess

import pytest
import pytrinamic.modules
from pytrinamic_links import connect, wait_until
from pytrinamic.tmcl import TMCLReplyStatusError
from tmclsim_binary import tmclsim_binary

# Classes for modules PyTrinamic has no class of: the closest one.
CLOSEST = {"TMCM1311": "tmcm-1310"}  # the closed-loop sibling of the TMCM-1310

# Parameters that change the link itself (address, host address, ASCII
# mode, suppressed replies, baud rate) or the program state are read only;
# a walk that wrote them would cut its own connection.
GP_LINK = {65, 66, 67, 76, 128, 129, 130, 255}
# Values that move on their own: written, not compared.
GP_MOVING = {132, 133}
# Motion parameters: driven through the motor API below.
AP_MOTION = {0, 1, 2}

ROW = re.compile(r"^\s+(\d+)\s+([RWEA]+)\s+(-?\d+)…(-?\d+)\s+(-?\d+) (manual|sibling|assumed)\s+(.*)$")


def profile_tables(profile):
    """{"axis": {n: (access, min, max)}, 0: {...}, 2: {...}, 3: {...}}."""
    text = subprocess.run([tmclsim_binary(), "profile", profile], capture_output=True, text=True, check=True).stdout
    tables, current = {}, None
    for line in text.splitlines():
        if line.startswith("Axis parameters"):
            current = tables.setdefault("axis", {})
        elif line.startswith("Global parameters, bank"):
            current = tables.setdefault(int(line.split()[-1]), {})
        elif current is not None and (m := ROW.match(line)):
            current[int(m.group(1))] = (m.group(2), int(m.group(3)), int(m.group(4)))
    return tables


def profile_axes(profile):
    """The module's number of axes (`tmclsim profile`'s first line)."""
    text = subprocess.run([tmclsim_binary(), "profile", profile], capture_output=True, text=True, check=True).stdout
    return int(re.search(r"(\d+) axis", text.splitlines()[0]).group(1))


def served_classes():
    """(class name, profile) for every PyTrinamic module class tmclsim serves."""
    pairs = []
    for name, cls in inspect.getmembers(pytrinamic.modules, inspect.isclass):
        digits = re.fullmatch(r"TMCM(\d+)", name)
        if not digits:
            continue
        profile = CLOSEST.get(name, f"tmcm-{digits.group(1)}")
        if subprocess.run([tmclsim_binary(), "profile", profile], capture_output=True).returncode == 0:
            pairs.append((name, profile))
    return pairs


CLASSES = served_classes()


def test_every_sibling_module_has_its_class():
    names = {name for name, _ in CLASSES}
    assert {"TMCM1110", "TMCM1140", "TMCM1141", "TMCM1160", "TMCM3110", "TMCM6110", "TMCM1311"} <= names, names


def enum(holder, name):
    """{NAME: number} of a class's parameter or IO enum."""
    e = getattr(holder, name, None)
    return {k: v for k, v in vars(e).items() if not k.startswith("_") and isinstance(v, int)} if e else {}


def probe(value, lo, hi):
    """A value within lo…hi that differs from `value`."""
    for v in (value + 1, value - 1, lo, hi):
        if lo <= v <= hi and v != value:
            return v
    return value


def refused(call):
    with pytest.raises(TMCLReplyStatusError) as err:
        call()
    return err.value.reply.status


@pytest.fixture(params=["tcp", "pty"])
def link(request):
    return request.param


@pytest.mark.parametrize("class_name,profile", CLASSES)
def test_every_named_parameter(serve, link, class_name, profile):
    cls = getattr(pytrinamic.modules, class_name)
    tables = profile_tables(profile)
    served = serve("--module", profile)
    with connect(served, link) as interface:
        module = cls(interface)
        motor_type = type(module.motors[0])
        axes = min(len(module.motors), profile_axes(profile))
        for axis in range(axes, len(module.motors)):
            assert refused(lambda: module.get_axis_parameter(1, axis)) == 4, f"{profile} has no motor {axis}"
        checked = 0
        for name, number in enum(motor_type, "AP").items():
            row = tables["axis"].get(number)
            for axis in range(axes):
                if row is None:
                    assert refused(lambda: module.get_axis_parameter(number, axis)) == 3, f"{profile} lacks AP {number} ({name})"
                    continue
                access, lo, hi = row
                value = module.get_axis_parameter(number, axis, signed=True) if "R" in access else None
                if "W" in access and number not in AP_MOTION and value is not None:
                    v = probe(value, lo, hi)
                    module.set_axis_parameter(number, axis, v)
                    assert module.get_axis_parameter(number, axis, signed=True) == v, f"{profile} AP {number} ({name}) axis {axis}"
                    module.set_axis_parameter(number, axis, value)
                checked += 1
        for enum_name, bank in (("GP0", 0), ("GP", 0), ("GP3", 3)):
            for name, number in enum(cls, enum_name).items():
                row = tables.get(bank, {}).get(number)
                if row is None:
                    assert refused(lambda: module.get_global_parameter(number, bank)) == 3, f"{profile} lacks GP {number}, {bank} ({name})"
                    continue
                access, lo, hi = row
                value = module.get_global_parameter(number, bank, signed=True) if "R" in access else None
                if "W" in access and number not in GP_LINK and value is not None:
                    v = probe(value, lo, hi)
                    module.set_global_parameter(number, bank, v)
                    if number not in GP_MOVING:
                        assert module.get_global_parameter(number, bank, signed=True) == v, f"{profile} GP {number}, {bank} ({name})"
                    module.set_global_parameter(number, bank, value)
                checked += 1
        assert checked > 40


@pytest.mark.parametrize("class_name,profile", CLASSES)
def test_motor_api(serve, link, class_name, profile):
    cls = getattr(pytrinamic.modules, class_name)
    speed = profile_tables(profile)["axis"][4][2]
    served = serve("--module", profile, "--world", "free")
    with connect(served, link) as interface:
        module = cls(interface)
        count = min(len(module.motors), profile_axes(profile))
        axes = sorted({0, count - 1})
        for axis in axes:
            motor = module.motors[axis]
            # PyTrinamic's linear ramp feature asks its class for
            # MaxVelocity; a class that names AP 4 otherwise (the TMCM1316
            # says MaxPositioningSpeed) raises AttributeError before asking
            # the module: the module's row is set by number there.
            if hasattr(motor.AP, "MaxVelocity"):
                motor.linear_ramp.max_velocity = min(speed, 2047)
                motor.linear_ramp.max_acceleration = min(speed, 2047)
                assert motor.linear_ramp.max_velocity == min(speed, 2047)
            else:
                motor.set_axis_parameter(4, min(speed, 2047))
                motor.set_axis_parameter(5, min(speed, 2047))
                assert motor.get_axis_parameter(4) == min(speed, 2047)
            module.move_to(axis, 5000)
            assert motor.target_position == 5000
            assert wait_until(lambda: motor.get_position_reached() == 1), f"{profile} axis {axis}"
            assert motor.actual_position == 5000
            module.move_by(axis, -2000)
            assert wait_until(lambda: motor.get_position_reached() == 1 and motor.actual_position == 3000)
            module.rotate(axis, 300)
            assert wait_until(lambda: motor.actual_velocity == 300), f"{profile} axis {axis} reaches the speed"
            module.stop(axis)
            assert wait_until(lambda: motor.actual_velocity == 0)
            motor.actual_position = 777
            assert motor.actual_position == 777
            settings = motor.drive_settings
            for attribute, ap in (("max_current", "MaxCurrent"), ("standby_current", "StandbyCurrent"), ("boost_current", "BoostCurrent")):
                # PyTrinamic reads the standby current only for a class that
                # names MaxCurrent (its TMCM1270 class says RunCurrent): its
                # getter answers None there without asking the module.
                if hasattr(motor.AP, ap) and (ap != "StandbyCurrent" or hasattr(motor.AP, "MaxCurrent")):
                    setattr(settings, attribute, 100)
                    assert getattr(settings, attribute) == 100, f"{profile} {attribute}"
            if hasattr(motor.AP, "MicrostepResolution"):
                settings.microstep_resolution = 6
                assert settings.microstep_resolution == 6
        # The other axes did not move.
        for axis in range(1, count - 1):
            assert module.motors[axis].actual_position == 0


# PyTrinamic's IO numbers the module's manual does not have: refused.
IO_NOT_ON_THE_MODULE = {
    # The TMCM-1141 manual's digital inputs are GIO 0…3, 0; the class says
    # IN3 = 4 (its TMCM-1140 numbering).
    ("TMCM1141", "IN3"),
}


@pytest.mark.parametrize("class_name,profile", CLASSES)
def test_io(serve, link, class_name, profile):
    cls = getattr(pytrinamic.modules, class_name)
    served = serve("--module", profile)
    with connect(served, link) as interface:
        module = cls(interface)
        for name, number in enum(cls, "IO").items():
            if (class_name, name) in IO_NOT_ON_THE_MODULE:
                assert refused(lambda: module.get_digital_input(number)) in (3, 4), name
            elif name.startswith("OUT"):
                module.set_digital_output(number)
                assert module.get_digital_output(number) == 1, name
                module.clear_digital_output(number)
                assert module.get_digital_output(number) == 0, name
            elif name in ("VIN", "Voltage"):
                assert module.get_analog_input(number) == 240, "the supply, 24.0 V"
            elif name == "Temperature":
                # GIO 9, 1 on the TMCM-1290: the module's temperature in °C.
                assert -50 <= module.get_analog_input(number) <= 150, name
            elif name.startswith("AIN"):
                assert 0 <= module.get_analog_input(number) <= 4095, name
            else:
                assert module.get_digital_input(number) in (0, 1), name
