"""PyTrinamic drives a closed-loop move on a virtual TMCM-1310 over the pty
(its TMCM-1311 class is the closest host class; raw commands where the
classes differ)."""

from pytrinamic.connections import ConnectionManager
from pytrinamic.modules import TMCM1311
from pytrinamic_links import wait_until


def test_closed_loop_move_over_the_pty(serve):
    served = serve("--module", "tmcm-1310", "--world", "free")
    args = f"--interface serial_tmcl --port {served.pty_link} --data-rate 115200"
    with ConnectionManager(args.split()).connect() as interface:
        assert interface.get_version_string() == "1310V114"
        module = TMCM1311(interface)
        motor = module.motors[0]
        motor.set_axis_parameter(motor.AP.ClosedLoopMode, 1)
        motor.set_axis_parameter(motor.AP.CLCurrentScaleMaximum, 100)
        motor.set_axis_parameter(motor.AP.MaxVelocity, 51200)  # pps: one turn a second
        served.world("load 0 60")
        interface.move_to(0, 51200)
        wait_until(lambda: interface.get_axis_parameter(8, 0), 10, "position reached (AP 8)",
                   seen=lambda: f"position {motor.get_axis_parameter(motor.AP.ActualPosition, signed=True)}")
        assert motor.get_axis_parameter(motor.AP.ActualPosition, signed=True) == 51200
        assert motor.get_axis_parameter(motor.AP.CLPositionError, signed=True) == 0
        status = motor.get_axis_parameter(motor.AP.StatusWord)
        assert status & 0b101 == 0b101  # target reached, closed loop active
        assert motor.get_axis_parameter(motor.AP.CLVirtualActualPosition, signed=True) == 51200
        scale = motor.get_axis_parameter(motor.AP.CLActualCurrentScaleFactor)
        assert scale >= 60, "the current follows the load"
