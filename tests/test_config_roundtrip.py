"""Every scenario's written config loads back (issue 26): ``config.toml`` of a run, given back with
``--config``, resolves to the same configuration (``--resume`` reads it the same way)."""

from __future__ import annotations

import pytest

from oceangnc.api import resolve_config
from oceangnc.io.config import dump_toml, to_dict
from oceangnc.scenarios.base import scenario_names


@pytest.mark.parametrize("name", scenario_names())
def test_the_written_config_loads_back_to_the_same_config(name, tmp_path):
    sc, cfg = resolve_config(name)
    path = tmp_path / "config.toml"
    dump_toml(cfg, path)
    _, again = resolve_config(config=path)
    assert to_dict(again) == to_dict(cfg)


@pytest.mark.parametrize("name", scenario_names())
def test_every_scenario_resumes_from_a_checkpoint_to_the_uninterrupted_log(name, tmp_path, monkeypatch):
    """A run cut after its last checkpoint (no compaction, no summary) resumes, through its own
    config.toml, to the log of an uninterrupted run."""
    import pandas as pd

    import oceangnc
    from oceangnc.errors import ConfigError
    from oceangnc.io.logs import LogWriter

    sc, cfg = resolve_config(name)
    if not sc.single_simulation(cfg):  # refused up front, before a folder is written
        with pytest.raises(ConfigError, match="checkpoint"):
            oceangnc.run(name, out=tmp_path / "cut", plots=False, checkpoint_every=1.0)
        assert not (tmp_path / "cut").exists()
        return
    dt = max(cfg.sim.dt, 0.05)
    dur = min(cfg.sim.duration, 400 * dt)
    every = round(dur / 2 / dt) * dt
    full = oceangnc.run(name, duration=dur, out=tmp_path / "full", plots=False).df
    orig = LogWriter.close
    monkeypatch.setattr(LogWriter, "close", lambda self: (setattr(self, "compact", False), orig(self))[1])
    res = oceangnc.run(name, duration=dur, out=tmp_path / "cut", plots=False, checkpoint_every=every,
                       overrides={"log.min_flush_wall_s": 0.0})  # fmt: skip
    monkeypatch.setattr(LogWriter, "close", orig)
    assert res.summary["checkpoints"] >= 1
    (tmp_path / "cut" / "summary.json").unlink()
    res2 = oceangnc.run(resume=tmp_path / "cut", plots=False)
    assert res2.summary["status"] == "ok" and res2.summary["resumed_from_t"] > 0
    pd.testing.assert_frame_equal(res2.df, full, check_exact=True)
