"""No thrust step after an emergency stop (issue 26), on every live scenario and both front ends: the
operator holds the stick (or the autopilot drives), e-stops for 10 s, resets (MAVLink: resets and
arms again); the thrusts come back as a ramp (oceangnc.models.actuators.thrusters_law), never as a
jump. Both front ends run with a fake clock, stepped by the test."""

from __future__ import annotations

import pytest

from mavlink_gcs import GCS
from oceangnc.console.messages import parse_message
from oceangnc.console.session import Session
from oceangnc.mavlink.live import live_scenarios
from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle
from oceangnc.models.actuators import RESUME_RAMP_S

#: what a thruster puts out (N); the first-order USV's engine (rpm); the ship's shaft speeds (rpm)
SUFFIXES = (".thrust_port", ".thrust_stbd", ".thrust_bow", "usv.rpm")
STATE_S = 0.04  # one 40 ms state message of the console


class FakeClock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self):
        return self.t


def _thrusts(bus) -> dict:
    """{output: (value, its command)} of every thruster / engine output on the bus."""
    return {
        k: (float(v), float(bus.get(k + "_cmd", 0.0)))
        for k, v in bus.items()
        if k.endswith(SUFFIXES) and not k.endswith("_cmd")
    }


def _check_ramp(before: list[dict], after: list[dict], name: str) -> int:
    """Every output that drove the vehicle before the stop comes back as a ramp: during the first
    RESUME_RAMP_S after the reset it stays within (t / RESUME_RAMP_S + one state) of its command's
    magnitude (so no step, whatever the controller asks), and then follows its command again."""
    checked = 0
    for k in before[-1]:
        if max(abs(r[k][0]) for r in before) < 1e-6:
            continue
        for i, r in enumerate(after):
            out, cmd = r[k]
            t = (i + 1) * STATE_S
            if t <= RESUME_RAMP_S:
                frac = t / RESUME_RAMP_S + 2 * STATE_S / RESUME_RAMP_S
                assert abs(out) <= frac * abs(cmd) + 1e-9, (
                    f"{name}: {k} = {out:.1f} at {t:.2f} s for a command {cmd:.1f}"
                )
        out, cmd = after[-1][k]
        assert out != 0.0 or cmd == 0.0, f"{name}: {k} does not come back"
        checked += 1
    return checked


DRIVEN = {"usv-remote", "combined-survey"}  # must have thrusts to check (the defect's scenarios)


@pytest.mark.parametrize("name", live_scenarios())
def test_console_reset_after_an_estop_ramps_the_thrust(name, tmp_path):
    clk = FakeClock()
    s = Session(name, out_root=tmp_path, clock=clk, write_log=False)
    s.client_connected()

    def run(seconds, rec=None):
        for _ in range(round(seconds / STATE_S)):
            clk.t += STATE_S
            s.submit(parse_message('{"type": "stick", "surge": 0.8, "yaw": 0.0}'))
            s.step_once()
            if rec is not None:
                rec.append(_thrusts(s.sim.bus))

    try:
        if name == "usv-remote":  # the operator's stick drives it (the defect's case)
            s.submit(parse_message('{"type": "mode", "mode": "remote"}'))
        before: list = []
        run(6.0, before)
        s.submit(parse_message('{"type": "estop", "engaged": true}'))
        run(STATE_S)
        assert all(v == 0.0 for v, _ in _thrusts(s.sim.bus).values()), "the e-stop zeroes every thrust at once"
        run(10.0)
        s.submit(parse_message('{"type": "estop", "engaged": false}'))
        after: list = []
        run(4.0, after)
    finally:
        s.stop()
    n = _check_ramp(before, after, name)
    assert n > 0 or name not in DRIVEN


@pytest.mark.parametrize("name", ["usv-remote", "combined-survey"])
def test_mavlink_reset_and_rearm_after_an_estop_ramps_the_thrust(name):
    clk = FakeClock()
    v = MavlinkVehicle(name, listen="udp:127.0.0.1:0", speed=1.0, out_root=None, clock=clk)
    g = GCS(v.address)

    def run(seconds, rec=None, stick=True):
        for _ in range(round(seconds / STATE_S)):
            clk.t += STATE_S
            g.mav.heartbeat_send(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            if stick:
                g.mav.manual_control_send(1, 800, 0, 0, 0, 0)
            v.step_once()
            if rec is not None:
                rec.append(_thrusts(v.sim.bus))

    def command(cmd, p1):
        g.mav.command_long_send(1, 1, cmd, 0, p1, 0, 0, 0, 0, 0, 0)
        run(STATE_S)

    try:
        command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        g.mav.set_mode_send(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 0)  # MANUAL
        before: list = []
        run(6.0, before)
        assert v.armed and v.mode == 0
        command(M.MAV_CMD_DO_FLIGHTTERMINATION, 1)
        assert v.estop and all(x == 0.0 for x, _ in _thrusts(v.sim.bus).values())
        run(10.0)
        command(M.MAV_CMD_DO_FLIGHTTERMINATION, 0)
        command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        assert v.armed and not v.estop
        after: list = []
        run(4.0, after)
    finally:
        g.close()
        v.stop()
    assert _check_ramp(before, after, name) > 0
