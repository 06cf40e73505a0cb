"""The block registry (issue 17): built-in kinds, picking a controller by ``kind`` from the config
and the command line, an unknown kind listing the registered ones, and a user's block from a
``--plugin`` file driving the flagship scenario."""

from __future__ import annotations

import json
import math
import textwrap

import pandas as pd
import pytest

from oceangnc.api import resolve_config
from oceangnc.cli import main
from oceangnc.core.registry import kinds, lookup, register_block
from oceangnc.errors import ConfigError

PLUGIN = '''
import math

from oceangnc.core.blocks import Block
from oceangnc.core.registry import register_block


@register_block("{kind}")
class ProportionalUUV(Block):
    """Stern thrust k_range * e_x (N), bow thrust k_heading * wrap(psi_usv - psi_uuv) (N)."""

    role = "controller"
    name = "uuv_control"

    def __init__(self, params, ctx):
        self.period = ctx.period
        self.k_range = float(params.get("k_range", 20.0))
        self.k_heading = float(params.get("k_heading", 10.0))
        self.psi_usv, self.psi_uuv = ctx.signal("usv.psi"), ctx.signal("uuv.psi")
        self.inputs = {{"lf.e_x": "m", self.psi_usv: "rad", self.psi_uuv: "rad"}}
        self.outputs = {{"uuv.thrust_port_cmd": "N", "uuv.thrust_stbd_cmd": "N", "uuv.thrust_bow_cmd": "N"}}

    def step(self, t, bus):
        e = (bus[self.psi_usv] - bus[self.psi_uuv] + math.pi) % (2 * math.pi) - math.pi
        bus["uuv.thrust_port_cmd"] = bus["uuv.thrust_stbd_cmd"] = self.k_range * bus["lf.e_x"]
        bus["uuv.thrust_bow_cmd"] = self.k_heading * e
'''


def test_builtin_kinds_registered():
    k = set(kinds())
    for name in (
        "uuv.pid",
        "uuv.backstepping",
        "usv.pid",
        "usv.pure_pursuit",
        "usv.los",
        "uuv.leader_follower",
        "sensor.gps",
        "sensor.ahrs",
        "sensor.usbl",
        "sensor.depth",
        "usv.thrusters",
        "uuv.thrusters",
        "env.current",
        "env.wind",
        "ship.pid",
        "ship.nonlinear",
        "ship.open",
    ):
        assert name in k, name
    assert kinds("uuv") == sorted(x for x in k if x.startswith("uuv."))


def test_register_twice_under_one_kind_is_refused():
    @register_block("test.once")
    class A:
        pass

    with pytest.raises(ValueError, match="registered twice"):

        @register_block("test.once")
        class B:
            pass


def test_lookup_unknown_kind_lists_family():
    with pytest.raises(ConfigError) as ei:
        lookup("uuv.lqr", "control.uuv.kind")
    msg = str(ei.value)
    assert msg.startswith("control.uuv.kind: unknown block kind 'uuv.lqr'; registered: ")
    assert "uuv.backstepping" in msg and "uuv.pid" in msg and "\n" not in msg


@pytest.mark.parametrize(
    "over",
    [{"control.uuv.kind": "backstepping"}, {"control.uuv": "backstepping"}, {"control.uuv.kind": "uuv.backstepping"}],
)
def test_kind_spellings_resolve_to_the_same_controller(over):
    _, cfg = resolve_config("combined-survey", overrides=over)
    assert cfg.control.uuv.full_kind == "uuv.backstepping"


def test_unknown_kind_is_one_line_config_error_listing_kinds(capsys):
    rc = main(["run", "combined-survey", "--set", "control.uuv.kind=lqr", "--duration", "1", "--quiet"])
    err = capsys.readouterr().err.strip()
    assert rc == 2
    assert err.count("\n") == 0
    assert "control.uuv.kind = 'lqr'" in err and "registered: uuv.backstepping, uuv.follow_tow, uuv.pid" in err


def test_cli_swaps_uuv_controller_by_kind(tmp_path):
    out = tmp_path / "bs"
    rc = main(
        [
            "run",
            "combined-survey",
            "--set",
            "control.uuv.kind=backstepping",
            "--duration",
            "2",
            "--no-plots",
            "--quiet",
            "--out",
            str(out),
        ]
    )
    assert rc == 0
    df = pd.read_parquet(out / "log.parquet")
    assert "uuv_bs.V" in df  # the backstepping block ran (its Lyapunov function is logged)
    assert (df["uuv_bs.V"] >= 0).all()
    assert 'kind = "backstepping"' in (out / "config.toml").read_text()


def test_user_controller_from_plugin_file_drives_the_flagship(tmp_path, capsys):
    plugin = tmp_path / "my_blocks.py"
    plugin.write_text(textwrap.dedent(PLUGIN.format(kind="my.ctrl")))
    out = tmp_path / "mine"
    rc = main(
        [
            "run",
            "combined-survey",
            "--plugin",
            str(plugin),
            "--set",
            "control.uuv.kind=my.ctrl",
            "--set",
            "control.uuv.k_heading=7.5",
            "--duration",
            "3",
            "--no-plots",
            "--quiet",
            "--json",
            "--out",
            str(out),
        ]
    )
    assert rc == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["status"] == "ok" and math.isfinite(summary["uuv.heading_error_rms_deg"])
    df = pd.read_parquet(out / "log.parquet")
    # every logged row: the commands are exactly the user's law on the signals of that instant
    e = (df["usv.psi"] - df["uuv.psi"] + math.pi) % (2 * math.pi) - math.pi
    assert (df["uuv.thrust_bow_cmd"] - 7.5 * e).abs().max() < 1e-9
    assert (df["uuv.thrust_port_cmd"] - 20.0 * df["lf.e_x"]).abs().max() < 1e-9
    assert "uuv_bs.V" not in df and "uuv_ctrl.loop" not in df  # neither built-in controller ran


def test_plugin_file_errors_are_input_errors(tmp_path, capsys):
    bad = tmp_path / "bad.py"
    bad.write_text("raise RuntimeError('boom')\n")
    rc = main(["run", "combined-survey", "--plugin", str(bad), "--duration", "1", "--quiet"])
    assert rc == 2
    assert "bad.py: RuntimeError: boom" in capsys.readouterr().err
    rc = main(["run", "combined-survey", "--plugin", str(tmp_path / "missing.py"), "--quiet"])
    assert rc == 2


def test_entry_point_group_registers_a_users_package(tmp_path):
    """An installed package declaring ``[project.entry-points."oceangnc.blocks"]`` is found on first lookup."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    pkg = tmp_path / "epdemo"
    pkg.mkdir()
    (pkg / "__init__.py").write_text(textwrap.dedent(PLUGIN.format(kind="epdemo.ctrl")))
    dist = tmp_path / "epdemo-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: epdemo\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[oceangnc.blocks]\nepdemo = epdemo\n")
    src = Path(__file__).resolve().parents[1] / "src"
    code = (
        "from oceangnc.api import resolve_config\n"
        "_, cfg = resolve_config('combined-survey', overrides={'control.uuv.kind': 'epdemo.ctrl'})\n"
        "print(cfg.control.uuv.full_kind)\n"
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), str(src)]))
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == "epdemo.ctrl"


def test_usv_controller_slot_takes_gains_and_refuses_unknown_ones():
    """``control.usv`` is a slot too: kind ``pid`` by default, its gains as keys of the slot."""
    import numpy as np

    sc, cfg = resolve_config("combined-survey", overrides={"control.usv.speed_kp": 700.0})
    assert cfg.control.usv.full_kind == "usv.pid" and cfg.control.usv.params == {"speed_kp": 700.0}
    sim = sc.build(cfg, np.random.default_rng(0))
    ctl = next(b for b in sim.blocks if b.name == "usv_control")
    assert ctl.speed.kp == 700.0 and ctl.heading.kp == 120.0  # the given gain, the others' defaults
    with pytest.raises(ConfigError, match=r"control\.usv: 'speed_kq' is not a parameter of kind 'pid'.*speed_kp"):
        resolve_config("combined-survey", overrides={"control.usv.speed_kq": 1.0})


def test_every_built_in_kind_is_an_entry_point_named_after_it():
    """The built-in blocks are found like a user's: through the ``oceangnc.blocks`` entry points of
    pyproject.toml, one per kind, named after it, pointing at the module that registers it (a kind
    missing there would be unknown until something imports its module; a wrong module would make
    the one-module lookup fall back to importing them all)."""
    import tomllib
    from pathlib import Path

    from oceangnc.core import registry

    root = Path(__file__).resolve().parents[1]
    src = root / "src"
    mods = {
        ".".join(p.relative_to(src).with_suffix("").parts)
        for p in (src / "oceangnc").rglob("*.py")
        if "\n@register_block(" in p.read_text()
    }
    eps = tomllib.loads((root / "pyproject.toml").read_text())["project"]["entry-points"]["oceangnc.blocks"]
    assert mods and mods == set(eps.values()), (sorted(mods - set(eps.values())), sorted(set(eps.values()) - mods))
    registry._load_entry_points()
    own = {k: c.__module__ for k, c in registry._KINDS.items() if c.__module__.startswith("oceangnc.")}
    assert own == eps


def test_a_kind_is_found_by_importing_its_module_only():
    """Resolving the flagship's kinds imports their modules and no other block module."""
    import subprocess
    import sys

    code = (
        "import sys\n"
        "from oceangnc.core.registry import full_kind\n"
        "print(full_kind('pid', 'usv'), full_kind('uuv.backstepping'))\n"
        "print(sorted(m for m in sys.modules if m.startswith('oceangnc.control.')))\n"
    )
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    kinds, mods = p.stdout.strip().splitlines()
    assert kinds == "usv.pid uuv.backstepping"
    assert "oceangnc.control.usv_control" in mods and "oceangnc.control.backstepping" in mods
    assert "oceangnc.control.berthing" not in mods and "oceangnc.control.joystick" not in mods
