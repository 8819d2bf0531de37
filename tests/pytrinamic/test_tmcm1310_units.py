"""PyTrinamic's TMCM1311 class (the closed-loop sibling's host class) drives
a served TMCM-1310 over TCP with the values of PyTrinamic's TMCM-1311
examples: velocities in pps and accelerations in pps² (docs/modules.md,
"Units of the motion parameters"), the closed-loop parameters by the
class's names, and the velocity range the TMCM-1311 manual V1.11 gives
(0…327 679 999 pps)."""

import time

import pytest
from pytrinamic.modules import TMCM1311
from pytrinamic.tmcl import TMCLReplyStatusError
from pytrinamic_links import connect, wait_until

# The velocity range of the TMCM-1311 manual V1.11 (AP 108/109), which the
# profile gives every velocity row.
VELOCITY_MAX = 327_679_999

# Closed-loop parameters the TMCM-1310 has, by the class's names: a value
# to write, in the row's units (velocities in pps).
WRITTEN = {
    "CLVelocityReachedWindow": 200,
    "CLFieldWeakeningMinimumVelocity": 100_000,
    "CLFieldWeakeningMaximimVelocity": VELOCITY_MAX,
    "CLEncoderOffset": 0,
    "CLCurrentScaleMinimum": 30,
    "CLCurrentScaleMaximum": 100,
    "CLCurrentScaleEnable": 1,
    "CLCorrectionVelocityP": 1000,
    "CLMaxFollowingError": 0,
    "CLMaxCorrectionVelocity": 20_000,
    "CLPositionReachedWindow": 10,
    "EncoderMode": 0,
    "FullstepResolution": 200,
    "EncoderResolution": 4000,
}
# And the ones the module measures: read only.
MEASURED = [
    "MaximumPossibleCurrent",
    "CLVelocityReached",
    "StatusWord",
    "CLTorqueModeActualCurrent",
    "CLActualCurrentScaleFactor",
    "MeasuredSpeed",
    "CLInitFlag",
    "EncoderPosition",
    "CLGamma",
    "CLVirtualActualPosition",
    "CLActualTargetCurrentScaleFactor",
    "CLPositionError",
]


def refused(call):
    with pytest.raises(TMCLReplyStatusError) as err:
        call()
    return err.value.reply.status


def test_the_tmcm1311_class_drives_a_tmcm1310_in_pps(serve):
    served = serve("--module", "tmcm-1310", "--world", "free")
    with connect(served, "tcp") as interface:
        assert interface.get_version_string() == "1310V114"
        module = TMCM1311(interface)
        motor = module.motors[0]
        ap = motor.AP

        # Closed loop on, as PyTrinamic's closed_loop_demo.py does it.
        motor.set_axis_parameter(ap.ClosedLoopMode, 1)
        assert wait_until(lambda: motor.get_axis_parameter(ap.CLInitFlag) == 1, 30)
        for name, value in WRITTEN.items():
            motor.set_axis_parameter(getattr(ap, name), value)
            assert motor.get_axis_parameter(getattr(ap, name), signed=True) == value, name
        for name in MEASURED:
            motor.get_axis_parameter(getattr(ap, name), signed=True)

        # The examples' ramp: 20000 pps, 40000 pps².
        motor.linear_ramp.max_velocity = 20_000
        motor.linear_ramp.max_acceleration = 40_000
        assert (motor.linear_ramp.max_velocity, motor.linear_ramp.max_acceleration) == (20_000, 40_000)

        # Velocities end at the sibling's range: one more answers status 4.
        motor.linear_ramp.max_velocity = VELOCITY_MAX
        assert motor.linear_ramp.max_velocity == VELOCITY_MAX
        for number in (ap.MaxVelocity, ap.CLFieldWeakeningMaximimVelocity, ap.CLMaxCorrectionVelocity, ap.StartStopVelocity):
            assert refused(lambda: motor.set_axis_parameter(number, VELOCITY_MAX + 1)) == 4, number
        assert refused(lambda: motor.rotate(VELOCITY_MAX + 1)) == 4
        assert refused(lambda: motor.set_axis_parameter(ap.MaxAcceleration, 0)) == 4
        # No pulse or ramp divisor: the 1311's supply readings at 153/154
        # are not modelled either.
        assert refused(lambda: motor.get_axis_parameter(ap.SupplyVoltage)) == 3
        motor.linear_ramp.max_velocity = 20_000

        # Rotate at the examples' 20000 pps.
        motor.actual_position = 0
        motor.rotate(20_000)
        assert wait_until(lambda: motor.actual_velocity == 20_000, 30)
        assert motor.target_velocity == 20_000
        assert wait_until(lambda: motor.get_axis_parameter(ap.MeasuredSpeed, signed=True) == 20_000, 30)
        assert wait_until(lambda: motor.get_axis_parameter(ap.CLVelocityReached) == 1, 30)
        assert motor.get_axis_parameter(ap.StatusWord) & 0b10110 == 0b10110, "velocity reached, closed loop, velocity mode"
        motor.stop()
        assert wait_until(lambda: motor.actual_velocity == 0, 30)

        # Absolute move: 51200 µsteps at 20000 pps and 40000 pps² take
        # 0.5 s up, 2.06 s at speed and 0.5 s down in virtual time, which
        # the served module keeps with the wall clock.
        motor.actual_position = 0
        motor.set_axis_parameter(ap.EncoderPosition, 0)
        started = time.monotonic()
        motor.move_to(51_200, 20_000)
        assert motor.target_position == 51_200
        assert wait_until(lambda: motor.get_position_reached() == 1, 60)
        assert time.monotonic() - started > 2.9, "20000 pps is 20000 µsteps per second"
        assert motor.actual_position == 51_200
        assert motor.get_axis_parameter(ap.CLVirtualActualPosition, signed=True) == 51_200
        assert motor.get_axis_parameter(ap.CLPositionError, signed=True) == 0
        assert motor.get_axis_parameter(ap.StatusWord) & 0b1101 == 0b1101, "target reached, closed loop, position mode"

        # Relative move, back by a quarter turn.
        motor.move_by(-12_800)
        assert motor.target_position == 38_400
        assert wait_until(lambda: motor.get_position_reached() == 1 and motor.actual_position == 38_400, 60)
        # The encoder (4000 counts a turn of 200 × 256 µsteps) saw the same.
        assert motor.get_axis_parameter(ap.EncoderPosition, signed=True) == 38_400 * 4000 // 51_200
