"""Declared signals and the wiring check (issue 17): one test per error kind, with its message.

The check runs when a :class:`~oceangnc.core.clock.Simulation` is built; each error names the block
and the signal. A plant's input that no block writes is an error at run time too (it used to read 0).
"""

from __future__ import annotations

import numpy as np
import pytest

from oceangnc.control.actuators import USVThrusterBlock
from oceangnc.control.usv_control import USVControlConfig, USVController
from oceangnc.core.blocks import FunctionBlock, Plant
from oceangnc.core.clock import Simulation
from oceangnc.core.signals import WiringError, check_wiring
from oceangnc.models.usv import USVConfig, USVPlant
from oceangnc.sensors.gps import GPS, GPSConfig


def _usv_loop(*extra, meas=None):
    cfg = USVConfig()
    ctl = USVController(USVControlConfig(), cfg, 0.5, 0.05, meas=meas)
    return [USVPlant(cfg)], [*extra, ctl, USVThrusterBlock(cfg, 0.05)]


def test_complete_usv_loop_passes_and_reports_units():
    plants, blocks = _usv_loop()
    sim = Simulation(plants, blocks, 0.01, 0.1)
    assert sim.signal_units["usv.thrust_port"] == "N"
    assert sim.signal_units["usv.psi"] == "rad"
    sim.run(1.0)
    assert sim.bus["usv.u"] > 0.4  # the loop drives toward 0.5 m/s from 0.5 m/s start: held near it


def test_missing_producer_names_block_and_signal():
    """A GPS on a mistyped body reads signals nothing writes."""
    plants, blocks = _usv_loop(GPS(GPSConfig(), body="usb"))
    with pytest.raises(WiringError) as ei:
        Simulation(plants, blocks, 0.01, 0.1)
    msg = str(ei.value)
    assert "block 'gps' reads 'usb.x' (m)" in msg
    assert "no block, plant or external source writes it" in msg


def test_missing_producer_for_a_controller_measurement():
    plants, blocks = _usv_loop(meas={"psi": "ahrs.psi"})
    with pytest.raises(WiringError, match=r"block 'usv_control' reads 'ahrs\.psi' \(rad\)"):
        Simulation(plants, blocks, 0.01, 0.1)


def test_double_writer_names_both_blocks_and_the_signal():
    cfg = USVConfig()
    plants, blocks = _usv_loop()
    second = USVController(USVControlConfig(), cfg, 0.3, 0.05)
    second.name = "usv_control_2"
    with pytest.raises(WiringError) as ei:
        Simulation(plants, [second, *blocks], 0.01, 0.1)
    assert str(ei.value) == ("signal 'usv.thrust_port_cmd' is written by two blocks: 'usv_control_2' and 'usv_control'")


def test_unit_mismatch_names_writer_reader_and_signal():
    """A command block writing the thrust command in V where the thrusters read N."""
    cfg = USVConfig()
    cmd = FunctionBlock(
        "command",
        0.05,
        lambda t, bus: None,
        inputs={},
        outputs={"usv.thrust_port_cmd": "V", "usv.thrust_stbd_cmd": "N"},
    )
    with pytest.raises(WiringError) as ei:
        Simulation([USVPlant(cfg)], [cmd, USVThrusterBlock(cfg, 0.05)], 0.01, 0.1)
    assert str(ei.value) == (
        "unit mismatch on 'usv.thrust_port_cmd': 'command' writes V but block 'usv_thrusters' reads N"
    )


def test_unknown_unit_is_refused():
    blk = FunctionBlock("b", 0.1, lambda t, bus: None, inputs={}, outputs={"x.speed": "knots"})
    with pytest.raises(WiringError, match=r"block 'b': signal 'x\.speed' declares unknown unit 'knots'"):
        check_wiring([blk])


def test_external_signal_counts_as_producer():
    """The console's stick is written from outside the loop: declared as external it satisfies a reader."""
    blk = FunctionBlock("pilot", 0.1, lambda t, bus: None, inputs={"joystick.surge": "1"}, outputs={})
    with pytest.raises(WiringError, match="joystick.surge"):
        check_wiring([blk])
    assert check_wiring([blk], external={"joystick.surge": "1"}) == {"joystick.surge": "1"}


def test_plant_input_nothing_writes_is_an_error_not_zero():
    """The USV's thrust inputs without thrusters: the check refuses the build (declared plant) ..."""
    cfg = USVConfig()
    with pytest.raises(WiringError, match=r"plant 'usv' reads 'usv\.thrust_port' \(N\)"):
        Simulation([USVPlant(cfg)], [], 0.01, 0.1)


def test_undeclared_plant_input_read_raises_at_run_time():
    """... and an undeclared plant whose input nobody writes fails on the first read instead of reading 0."""
    from numba import njit

    @njit(cache=False)
    def rhs(t, x, u, p, out):
        out[0] = u[0]

    plant = Plant("p", rhs, [0.0], [0.0], ["x"], ["p.u"])
    sim = Simulation([plant], [FunctionBlock("typo", 0.1, lambda t, bus: bus.__setitem__("p.uu", 1.0))], 0.01, 0.1)
    with pytest.raises(WiringError, match=r"plant 'p' reads 'p\.u' but no block has written it"):
        sim.run(0.1)
    # with a documented default the same plant runs and integrates the default
    plant2 = Plant("p", rhs, [0.0], [0.0], ["x"], ["p.u"], input_defaults={"p.u": 2.0})
    Simulation([plant2], [], 0.01, 0.1).run(0.5)
    assert plant2.x[0] == pytest.approx(1.0, abs=1e-12)


def test_plant_declarations_from_units():
    p = USVPlant(USVConfig())
    assert p.inputs == {"usv.thrust_port": "N", "usv.thrust_stbd": "N"}
    assert p.optional_inputs == {
        "env.current_n": "m/s",
        "env.current_e": "m/s",
        "env.wind_n": "m/s",
        "env.wind_e": "m/s",
    }
    assert p.outputs["usv.speed"] == "m/s" and p.outputs["usv.r"] == "rad/s"
    assert np.isfinite(p.x).all()


def test_the_log_schema_comes_from_the_declarations():
    """The log's columns are the declared outputs (plants and blocks, numbers only); a block that
    writes a scalar it does not declare is refused at the first tick, naming the signal."""
    cfg = USVConfig()
    cmd = FunctionBlock(
        "command", 0.05, lambda t, bus: bus.update({"usv.thrust_port_cmd": 10.0, "usv.thrust_stbd_cmd": 10.0}),
        inputs={}, outputs={"usv.thrust_port_cmd": "N", "usv.thrust_stbd_cmd": "N"},
    )  # fmt: skip

    class Rows(list):
        def append(self, t, row):  # the log interface of Simulation.run
            super().append((t, row))

    sim = Simulation([USVPlant(cfg)], [cmd, USVThrusterBlock(cfg, 0.05)], dt=0.01, log_period=0.1)
    sim.run(0.1, log=Rows())
    declared = {k for p in [*sim.plants, *sim.blocks] for k, u in p.outputs.items() if u != "str"}
    assert set(sim.log_signals) == {k for k in declared if not k.startswith("_")}

    def sloppy(t, bus):
        bus.update({"usv.thrust_port_cmd": 10.0, "usv.thrust_stbd_cmd": 10.0, "debug.note": 1.0})

    cmd2 = FunctionBlock(
        "command", 0.05, sloppy, inputs={}, outputs={"usv.thrust_port_cmd": "N", "usv.thrust_stbd_cmd": "N"}
    )
    sim = Simulation([USVPlant(cfg)], [cmd2, USVThrusterBlock(cfg, 0.05)], dt=0.01, log_period=0.1)
    with pytest.raises(WiringError, match="signal 'debug.note' is on the bus after the first tick but no block"):
        sim.run(0.1, log=Rows())
