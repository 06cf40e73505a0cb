"""No thrust step after an emergency stop or a failsafe (issue 26), on every live scenario and both front
ends: the operator holds the stick (or the autopilot drives), the thrust is cut - an e-stop for 10 s, or
a stick stream that falls silent (failsafe) - and is given back (console: Reset, or the stick centred
and pushed again; MAVLink: reset and arm again, or the ground station back in its driving mode); the
thrusts come back as a ramp (:mod:`oceangnc.core.estop`), never as a jump. Both front ends run with a
fake clock, stepped by the test.

The signals checked are found from the declarations, not from their names: every plant input in force
(N, N m) or shaft-speed (rpm, Hz) units that a block writes (:func:`actuator_outputs`)."""

from __future__ import annotations

import math

import pytest

from mavlink_gcs import GCS
from oceangnc.console.messages import parse_message
from oceangnc.console.session import Session
from oceangnc.mavlink.live import live_scenarios
from oceangnc.mavlink.protocol import AUTO, MANUAL
from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle
from oceangnc.models.actuators import RESUME_RAMP_S

STATE_S = 0.04  # one 40 ms state message of the console
SLACK_S = 0.16  # the ramp's time allowance: the state in which it starts, and a block period (up to 0.1 s)
EARLY_S = 0.5  # s after the reset in which a signal without a known demand is checked against its peak
BEFORE_S, BEFORE_MAX_S = 6.0, 30.0  # driving before the cut: 6 s, longer (up to 30 s) until a thrust is on
DRIVE_UNITS = ("N", "N m", "rpm", "Hz")

#: live scenarios that drive no thruster by design (their actuator outputs stay zero); every other live
#: scenario must have outputs to check, on both front ends
IDLE = {
    "tow-deploy": "the winch pays out the cable with the USV's and UUV's thrusters off (ThrustersOff)",
    "cable-current": "a moored cable in a current: no thrusters",
}


class FakeClock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self):
        return self.t


def actuator_outputs(sim) -> dict[str, str | None]:
    """{signal: the raw demand it follows, or None} for every force (N, N m) or shaft speed (rpm, Hz)
    input of a plant that a block writes: what the control side hands to the physics (thrusts of the
    thruster banks, thrust commands of an allocation to a plant with thruster lags, the ship's shaft
    commands, the first-order USV's engine). The raw demand is ``<signal>_cmd`` when a block that is not
    an actuator writes it (a controller or a constant: the command before the actuator's ramp)."""
    blocks = [getattr(b, "block", b) for b in sim.blocks]
    written = {k for b in blocks for k in (b.outputs or {})}
    demand = {k for b in blocks if getattr(b, "role", None) != "actuator" for k in (b.outputs or {})}
    outs: dict[str, str | None] = {}
    for p in sim.plants:
        units = {**(p.inputs or {}), **(p.optional_inputs or {})}
        for k in p.input_names:
            if units.get(k) in DRIVE_UNITS and k in written:
                outs[k] = k + "_cmd" if k + "_cmd" in demand else None
    return outs


def _record(bus, outs) -> dict:
    """{output: (value, its raw demand or nan)}."""
    return {k: (float(bus.get(k, 0.0)), float(bus.get(c, 0.0)) if c else math.nan) for k, c in outs.items()}


def _check_ramp(before: list[dict], after: list[dict], name: str) -> int:
    """Every signal that drove the vehicle before the cut comes back as a ramp, not a step: during the
    first RESUME_RAMP_S after the thrust is given back it stays within (t + SLACK_S) / RESUME_RAMP_S
    of its raw demand's magnitude where that is known (whatever the controller asks); where it is not
    (a thrust allocation's commands, a ship's shaft commands), during the first EARLY_S within that
    fraction of the largest magnitude it reaches in the record (a step lands at the order of that
    magnitude in the first state: 10 % allowed there). It is not zero at the end (it comes back).
    Returns the number of signals checked."""
    checked = 0
    for k in before[-1]:
        if max(abs(r[k][0]) for r in before) < 1e-6:
            continue
        peak = max(abs(r[k][0]) for r in before + after)
        for i, r in enumerate(after):
            out, cmd = r[k]
            t = (i + 1) * STATE_S
            frac = (t + SLACK_S) / RESUME_RAMP_S
            if not math.isnan(cmd) and t <= RESUME_RAMP_S:
                assert abs(out) <= frac * abs(cmd) + 1e-9, (
                    f"{name}: {k} = {out:.3g} at {t:.2f} s for a command {cmd:.3g}"
                )
            elif math.isnan(cmd) and t <= EARLY_S:
                assert abs(out) <= frac * peak + 1e-9, f"{name}: {k} = {out:.3g} at {t:.2f} s (largest {peak:.3g})"
        out, cmd = after[-1][k]
        assert out != 0.0 or cmd == 0.0, f"{name}: {k} does not come back"
        checked += 1
    return checked


def _driving(rec: list[dict]) -> bool:
    return bool(rec) and any(abs(v) > 1e-6 for v, _ in rec[-1].values())


def _expect_checked(name: str, n: int, outs: dict) -> None:
    if name in IDLE:
        assert n == 0, f"{name} is listed as idle ({IDLE[name]}) but drove {n} outputs"
    else:
        assert outs, f"{name}: no actuator output found in its blocks' declarations"
        assert n > 0, f"{name}: none of its actuator outputs {sorted(outs)} drove the vehicle before the stop"


# -- the console ----------------------------------------------------------------------------------------


class _Console:
    def __init__(self, name, tmp_path):
        self.clk = FakeClock()
        self.s = Session(name, out_root=tmp_path, clock=self.clk, write_log=False)
        self.s.client_connected()
        self.outs = actuator_outputs(self.s.sim)

    def send(self, text: str) -> None:
        self.s.submit(parse_message(text))

    def run(self, seconds, rec=None, stick=(0.8, 0.0)):
        for _ in range(round(seconds / STATE_S)):
            self.clk.t += STATE_S
            if stick is not None:
                self.send(f'{{"type": "stick", "surge": {stick[0]}, "yaw": {stick[1]}}}')
            self.s.step_once()
            if rec is not None:
                rec.append(_record(self.s.sim.bus, self.outs))

    def thrusts(self) -> list[float]:
        return [v for v, _ in _record(self.s.sim.bus, self.outs).values()]


@pytest.mark.parametrize("name", live_scenarios())
def test_console_reset_after_an_estop_ramps_the_thrust(name, tmp_path):
    c = _Console(name, tmp_path)
    try:
        if name == "usv-remote":  # the operator's stick drives it (the defect's case)
            c.send('{"type": "mode", "mode": "remote"}')
        before: list = []
        c.run(BEFORE_S, before)
        while not _driving(before) and len(before) * STATE_S < BEFORE_MAX_S:
            c.run(1.0, before)
        c.send('{"type": "estop", "engaged": true}')
        c.run(STATE_S)
        assert all(v == 0.0 for v in c.thrusts()), "the e-stop zeroes every thrust at once"
        c.run(10.0)
        c.send('{"type": "estop", "engaged": false}')
        after: list = []
        c.run(4.0, after)
    finally:
        c.s.stop()
    _expect_checked(name, _check_ramp(before, after, name), c.outs)


@pytest.mark.parametrize("name", live_scenarios())
def test_console_stick_failsafe_clearing_ramps_the_thrust(name, tmp_path):
    """Remote mode, stick at 0.8; the stick falls silent for 3 s (failsafe: thrust zero); it comes back
    centred (the failsafe clears) and is pushed to 0.8 again at once: the thrust ramps."""
    c = _Console(name, tmp_path)
    try:
        c.send('{"type": "mode", "mode": "remote"}')
        before: list = []
        c.run(BEFORE_S, before)
        while not _driving(before) and len(before) * STATE_S < BEFORE_MAX_S:
            c.run(1.0, before)
        c.run(3.0, stick=None)
        assert c.s.failsafe
        if not c.s.station_keep:
            assert all(v == 0.0 for v in c.thrusts()), "the failsafe zeroes every thrust"
        c.run(STATE_S, stick=(0.0, 0.0))
        assert not c.s.failsafe, "a centred stick clears the failsafe"
        after: list = []
        c.run(4.0, after)
    finally:
        c.s.stop()
    _expect_checked(name, _check_ramp(before, after, name), c.outs)


# -- MAVLink ---------------------------------------------------------------------------------------------


class _Mavlink:
    """A MAVLink vehicle and a ground station; ``drive`` is MANUAL with the stick for a scenario that
    follows it, else AUTO (the scenario's own guidance; MANUAL is refused there)."""

    def __init__(self, name):
        self.clk = FakeClock()
        self.v = MavlinkVehicle(name, listen="udp:127.0.0.1:0", speed=1.0, out_root=None, clock=self.clk)
        if self.v.sub1 is not None:  # a ROV is an ArduSub system 1: its ramp and failsafes are ArduSub's
            self.v.stop()
            pytest.skip("ArduSub system 1 (ROV): tests/test_mavlink_ardusub.py (e-stop ramp, GCS failsafe)")
        self.g = GCS(self.v.address)
        self.outs = actuator_outputs(self.v.sim)
        self.drive = MANUAL if self.v.reads_stick else AUTO

    def run(self, seconds, rec=None, stick=True, heartbeat=True):
        for _ in range(round(seconds / STATE_S)):
            self.clk.t += STATE_S
            if heartbeat:
                self.g.mav.heartbeat_send(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            if stick:
                self.g.mav.manual_control_send(1, 800, 0, 0, 0, 0)
            self.v.step_once()
            if rec is not None:
                rec.append(_record(self.v.sim.bus, self.outs))

    def command(self, cmd, p1):
        self.g.mav.command_long_send(1, 1, cmd, 0, p1, 0, 0, 0, 0, 0, 0)
        self.run(STATE_S, stick=self.drive == MANUAL)

    def set_drive_mode(self):
        self.g.mav.set_mode_send(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, self.drive)
        self.run(STATE_S, stick=self.drive == MANUAL)
        assert self.v.mode == self.drive, f"mode {self.v.mode}, asked {self.drive}"

    def thrusts(self) -> list[float]:
        return [v for v, _ in _record(self.v.sim.bus, self.outs).values()]

    def arm_and_drive(self) -> list[dict]:
        """Arm, select the driving mode, drive for BEFORE_S (longer, up to BEFORE_MAX_S, until a thrust
        is on); returns the record."""
        stick = self.drive == MANUAL
        self.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        self.set_drive_mode()
        before: list = []
        self.run(BEFORE_S, before, stick=stick)
        while not _driving(before) and len(before) * STATE_S < BEFORE_MAX_S:
            self.run(1.0, before, stick=stick)
        return before

    def drive_after(self) -> list[dict]:
        """The record of 4 s of driving after the thrust is given back."""
        after: list = []
        self.run(4.0, after, stick=self.drive == MANUAL)
        return after

    def close(self):
        self.g.close()
        self.v.stop()


@pytest.mark.parametrize("name", live_scenarios())
def test_mavlink_reset_and_rearm_after_an_estop_ramps_the_thrust(name):
    f = _Mavlink(name)
    stick = f.drive == MANUAL
    try:
        before = f.arm_and_drive()
        assert f.v.armed and f.v.mode == f.drive
        f.command(M.MAV_CMD_DO_FLIGHTTERMINATION, 1)
        assert f.v.estop and all(x == 0.0 for x in f.thrusts())
        f.run(10.0, stick=stick)
        f.command(M.MAV_CMD_DO_FLIGHTTERMINATION, 0)
        f.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        assert f.v.armed and not f.v.estop
        if f.v.mode != f.drive:
            f.set_drive_mode()
        after = f.drive_after()
    finally:
        f.close()
    _expect_checked(name, _check_ramp(before, after, name), f.outs)


@pytest.mark.parametrize("silent", ["link", "stick"])
@pytest.mark.parametrize("name", live_scenarios())
def test_mavlink_failsafe_clearing_ramps_the_thrust(name, silent):
    """The ground station falls silent for 6 s - all of it (``link``: the GCS failsafe, FS_GCS_TIMEOUT) or
    only its stick stream, heartbeats going on (``stick``: the stick failsafe, FS_TIMEOUT) - and the
    vehicle goes to HOLD (FS_ACTION); then the ground station selects its driving mode again with the
    stick held at 0.8: the thrust ramps from what HOLD left (zero where the scenario cannot hold on a
    zero stick). A scenario flown in AUTO has no stick stream: stick silence trips nothing there."""
    f = _Mavlink(name)
    stick = f.drive == MANUAL
    try:
        before = f.arm_and_drive()
        f.run(6.0, stick=False, heartbeat=silent == "stick")
        if silent == "stick" and not stick:
            assert not f.v.failsafe and f.v.mode == AUTO, "no stick stream, no stick failsafe"
            return
        # all silent in a stick mode: the stick failsafe (RC_OVERRIDE_TIME, 3 s) trips before the GCS one
        # (FS_GCS_TIMEOUT, 5 s), which HOLD then leaves untriggered, as ArduPilot Rover orders them (issue 39)
        assert f.v.failsafe or f.v.stick_failsafe, f"{silent} silence trips a failsafe"
        assert f.v.mode != f.drive, f"{silent} silence leaves the driving mode (FS_ACTION)"
        f.run(1.0, stick=False)
        f.set_drive_mode()
        after = f.drive_after()
    finally:
        f.close()
    _expect_checked(name, _check_ramp(before, after, name), f.outs)
