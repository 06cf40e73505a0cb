"""Every run can be stopped and bounded, and says truly what an interrupt kept (issue 41).

* ``--set sim.dt=1e-12 --duration 1`` (10^12 physics steps) was accepted and ran for days, deaf to
  SIGTERM: refused now in one line that says how long it would take, before any folder is made.
* A physics step so small that one clock tick is more steps than the loop may take without returning
  to Python (where a signal is handled) is refused too.
* An interrupt before the run's log is open, or after the simulation (while the log is read back for
  the summary), printed "summary.json status: interrupted" and wrote no summary.json.
"""

from __future__ import annotations

import json

import pytest

from oceangnc import api
from oceangnc.cli import main
from oceangnc.errors import Terminated


def test_a_run_of_10_to_the_12_steps_is_refused_in_one_line(tmp_path, capsys):
    out = tmp_path / "run"
    rc = main(["run", "usv-turn", "--set", "sim.dt=1e-12", "--duration", "1", "--out", str(out), "--no-plots"])
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1, err
    assert "1e+12 physics steps" in err and "5.79 days" in err and "sim.dt" in err
    assert not out.exists()


def test_a_tick_longer_than_a_signal_may_wait_is_refused(tmp_path, capsys):
    out = tmp_path / "run"
    rc = main(["run", "usv-turn", "--set", "sim.dt=1e-7", "--duration", "0.05", "--out", str(out), "--no-plots"])
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1, err
    assert "physics steps between two block firings" in err and "raise sim.dt" in err
    assert not out.exists()  # refused before it simulated: nothing left behind


def test_sigterm_before_the_log_is_open_says_no_summary_was_written(tmp_path, capsys, monkeypatch):
    def stopped(*a, **k):
        raise Terminated()

    monkeypatch.setattr(api.LogWriter, "for_run", stopped)
    out = tmp_path / "run"
    assert main(["run", "usv-turn", "--duration", "2", "--out", str(out), "--no-plots"]) == 143
    err = capsys.readouterr().err
    assert "no summary written" in err and "summary.json status: interrupted" not in err, err
    assert not (out / "summary.json").exists()


@pytest.mark.parametrize("exc", [KeyboardInterrupt, Terminated])
def test_an_interrupt_after_the_simulation_writes_the_interrupted_summary(tmp_path, capsys, monkeypatch, exc):
    def stopped(*a, **k):
        raise exc()

    monkeypatch.setattr(api, "read_table", stopped)  # the log read back for the summary
    out = tmp_path / "run"
    rc = main(["run", "usv-turn", "--duration", "2", "--out", str(out), "--no-plots"])
    err = capsys.readouterr().err
    assert rc == (143 if exc is Terminated else 130)
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "interrupted" and s["signal"] == ("SIGTERM" if exc is Terminated else "SIGINT")
    assert f"summary.json status: interrupted in {out} ({s['rows']} log rows kept)" in err
    assert s["rows"] == 41  # 2 s at 20 Hz, t = 0 included: the whole log, closed
