"""The three-point bridle of 003 fig. 5-6 (cable.attachment = "bridle"): statics against closed-form balances,
tension-only wires, the pitch stiffness against r . F, the config's errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from oceangnc.errors import ConfigError
from oceangnc.models._combined_bridle import B_RJ, B_T, pitch_stiffness
from oceangnc.models.cable import CableConfig
from oceangnc.models.combined import H_BRI, CombinedPlant
from oceangnc.models.usv import USVConfig
from oceangnc.models.uuv import UUVConfig

BUS = {"env.current_n": 0.0, "env.current_e": 0.0}


def hang(bridle: dict, seconds: float = 40.0, **cable):
    """A UUV hanging on the bridle under a fixed top point in still water: (plant, o_uuv, bus)."""
    cc = CableConfig(attachment="bridle", integrator="imex", bridle=bridle, **cable)
    pl = CombinedPlant(USVConfig(), UUVConfig(z0=3.7), cc, top="fixed")
    pl.reset()
    t = 0.0
    while t < seconds - 1e-9:
        t = pl.advance(t, 0.01, 100)
    bus = dict(BUS)
    pl.publish(bus)
    return pl, pl.o_uuv, bus


def test_the_hull_hangs_at_the_statics_pitch_of_its_apex():
    """Still water, wires rigged to an apex r_A: the moment balance about the CB, T (z_A sin th + x_A cos th)
    = W z_G sin th (r_A x F of 003 eq. 2.33 with the force T straight up, the restoring moment of the CG z_G
    below the CB), gives tan th = x_A T / (-z_A T + W z_G). Level for the apex over the CB, 24 deg nose up
    for an apex 0.3 m ahead of it; the single point's formula on the junction the model solved."""
    uc = UUVConfig()
    wz = uc.weight * uc.zg
    for ax in (0.0, 0.3):
        pl, o, bus = hang({"apex_x": ax, "apex_z": -0.625})
        rj = pl.p[int(pl.p[H_BRI]) + B_RJ : int(pl.p[H_BRI]) + B_RJ + 3]
        T = bus["cable.bottom_tension"]
        th = math.atan2(rj[0] * T, -rj[2] * T + wz)
        assert math.degrees(pl.x[o + 4]) == pytest.approx(math.degrees(th), abs=0.3)
        assert abs(pl.x[o + 3]) < 1e-6  # no roll in the symmetric hang
    assert math.degrees(th) > 20.0  # the apex ahead of the CB pitches the hull nose up


def test_the_wires_carry_the_cable_force_and_only_in_tension():
    """The three wire tensions (N) balance the cable's force on the junction (sum of T_i u_i + F = 0 to 0.5 N
    while the hull settles); a fore wire longer than the apex distance goes slack (zero tension), and the
    vertical mid wire above the CB then carries the whole force (the aft wire just taut)."""
    pl, o, bus = hang({"apex_z": -0.625})
    ob = int(pl.p[H_BRI])
    T = pl.p[ob + B_T : ob + B_T + 3]
    assert (T > 10.0).all() and T[0] == pytest.approx(T[2], rel=1e-3)  # symmetric rig
    hull = np.array(CableConfig().bridle.points())
    rj = pl.p[ob + B_RJ : ob + B_RJ + 3]
    u = (hull - rj) / np.linalg.norm(hull - rj, axis=1)[:, None]
    pull = (T[:, None] * u).sum(axis=0)  # the wires' pull on the junction, body frame ~ vertical at theta ~ 0
    assert np.linalg.norm(pull) == pytest.approx(bus["cable.bottom_tension"], rel=0.01)
    pl2, _, bus2 = hang({"apex_z": -0.625, "length_fore": 1.5})
    T2 = pl2.p[int(pl2.p[H_BRI]) + B_T : int(pl2.p[H_BRI]) + B_T + 3]
    assert T2[0] == 0.0 and T2[1] == pytest.approx(bus2["cable.bottom_tension"], rel=0.02) and T2[2] < 1.0


def test_pitch_stiffness_of_the_bridle_is_its_apex_lever():
    """k = -dM/dtheta through the model equals r . F_b for a rigid attachment (003 eq. 2.33 differentiated):
    the single point to 1e-6, the bridle to 0.5 % (the wires stretch); the bridle's apex 1.0 m above the CB
    is eight times the single point's 0.125 m lever."""
    uc = UUVConfig()
    for lean in (0.0, 12.0):
        a = math.radians(lean)
        F = 150.0 * np.array([math.sin(a), 0.0, -math.cos(a)])
        k1, r1 = pitch_stiffness(CableConfig(), uc, 150.0, lean)
        kb, rb = pitch_stiffness(CableConfig(attachment="bridle"), uc, 150.0, lean)
        assert k1 == pytest.approx(float(np.array(CableConfig().tow_point) @ F), rel=1e-6)
        assert kb == pytest.approx(float(np.array([0.0, 0.0, -1.0]) @ F), rel=5e-3)
        assert kb / k1 == pytest.approx(8.0, rel=0.01)


def test_single_point_leaves_no_bridle_block_and_bad_keys_are_refused():
    pl = CombinedPlant(USVConfig(), UUVConfig(), CableConfig(), top="fixed")
    assert pl.p[H_BRI] == 0.0
    with pytest.raises(ValueError, match="attachment"):
        CableConfig(attachment="rope")
    with pytest.raises(ValueError, match="apex_z"):
        CableConfig(attachment="bridle", bridle={"apex_z": -30.0})
    with pytest.raises((ConfigError, ValueError), match="length_mid"):
        CableConfig(attachment="bridle", bridle={"apex_x": 0.0, "apex_z": -0.125})


def test_cli_bad_bridle_key_is_one_line_exit_2(capsys):
    from oceangnc.cli import main

    assert main(["run", "field-test", "--set", "cable.bridle.apex_z=-50", "--no-plots", "--duration", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cable.bridle.apex_z" in err[0] and "-20" in err[0]


def test_a_snatch_on_the_bridle_does_not_roll_the_hull():
    """The field test's start (issue 38): the UUV released 3 m deep on 3 m of cable with the junction 1 m above
    its centre, so the cable is slack by the bridle's height; the UUV falls and the cable snatches taut (the wires
    carry 0.8 kN for a step) while the stern thrusters back it away (2 x -31 N) and the bow thruster pushes
    sideways (-3 N), as the PID does at the start. A colinear bridle restores roll only by the cable's tension on
    the hull's top line, 0.125 m above the CB, and W z_G: the roll stays under 10 deg. Before the junction's
    Newton kept its best point (backtracking on the balance's residual), an unconverged solve left the junction
    where up to 700 N were unbalanced under the snatch, and the hull rolled 44 deg in 0.8 s (62.7 deg in the
    field test, and over 700 deg on a 2 m bridle)."""
    cc = CableConfig(attachment="bridle", integrator="imex")
    pl = CombinedPlant(USVConfig(), UUVConfig(z0=3.0), cc, top="usv")
    pl.reset()
    o = pl.o_uuv
    pl.u[6] = pl.u[7] = -31.0  # uuv.thrust_port, uuv.thrust_stbd (N)
    pl.u[8] = -3.0  # uuv.thrust_bow (N)
    t, roll, wire = 0.0, 0.0, 0.0
    for _ in range(150):  # 1.5 s: the fall, the snatch (~0.4 s) and the first rebound
        t = pl.advance(t, 0.01, 1)
        roll = max(roll, abs(math.degrees(pl.x[o + 3])))
        wire = max(wire, pl.p[int(pl.p[H_BRI]) + B_T : int(pl.p[H_BRI]) + B_T + 3].max())
    assert wire > 300.0  # the snatch happened (the wires take several times the UUV's 118 N)
    assert roll < 10.0


def test_the_built_cable_hangs_the_uuv_at_the_field_tests_start_depth():
    """field-test's fitted rig (scenarios/combined.py _BUILT: apex 1.25 m, cable paid out to 1.692 m) hangs the
    UUV at 003's initial 3 m (fig 6-17) in still water, so the run starts without a drop onto a slack cable:
    the centre settles within 3 cm of 3 m. On 3 m of cable the same bridle hangs it 1.2 m deeper."""
    from oceangnc.scenarios.combined import _BUILT

    cc = CableConfig(**_BUILT)
    assert cc.attachment == "bridle" and cc.bridle.apex_z < -1.0
    pl = CombinedPlant(USVConfig(), UUVConfig(z0=3.0), cc, top="fixed")
    pl.reset()
    t = 0.0
    while t < 20.0 - 1e-9:
        t = pl.advance(t, 0.01, 100)
    assert pl.x[pl.o_uuv + 2] == pytest.approx(3.0, abs=0.03)
    assert abs(math.degrees(pl.x[pl.o_uuv + 4])) < 0.5  # level: the apex over the CB
