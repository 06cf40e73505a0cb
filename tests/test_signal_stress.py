"""Ctrl-C and SIGTERM at random instants, hundreds of times, never crash a run nor get lost (issue 41).

One long-lived child runs ``oceangnc run usv-turn`` (its ``main`` in-process, cached, 0.2 s a run)
over and over; this test sends it SIGINT or SIGTERM at random instants (every phase: argument
parsing, config, the run folder, building the simulation, the fused loop, log flushes, the log's
merge, the summary). Before the fix SIGINT kept Python's default handler, which raises anywhere: at
random instants of a cached run it ended in SIGSEGV inside the fused driver's call (rc -11, 2 in 34
in the issue, 1 in 50 here) or was swallowed (the run went on to status ok); and an interrupt
before the run folder or after the simulation printed "summary.json status: interrupted" with no
summary written.

Checked for every signal: the child is alive (no crash); the run it lands in ends interrupted
(exit 130 or 143), or, when it lands between two runs, in the child's own loop; never a run that
ends normally more than a few tenths of a second after the signal (a lost signal); and what the
message says was kept is on disk (summary.json interrupted, a finished run's ok summary, or none
when it says none).
"""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import threading
import time
from queue import Empty, Queue

import pytest

SIGNALS = 200  # signals sent; about 20 s at a mean interval of 0.1 s

CHILD = r"""
import contextlib, io, json, signal, sys, time
from pathlib import Path
from oceangnc.cli import main
from oceangnc.errors import Terminated

out = Path(sys.argv[1])
argv = ["run", "usv-turn", "--duration", "300", "--out", str(out), "--overwrite", "--quiet", "--no-plots"]

def between(signum, frame):  # a signal between two runs (main's handlers are not installed then)
    raise Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()

while True:
    signal.signal(signal.SIGTERM, between)
    signal.signal(signal.SIGINT, between)
    try:
        (out / "summary.json").unlink(missing_ok=True)
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            rc = main(argv)
        t_end = time.monotonic()
        try:
            st = json.loads((out / "summary.json").read_text())["status"]
        except OSError:
            st = "missing"
        print(json.dumps({"rc": rc, "status": st, "err": err.getvalue()[-400:], "t_end": t_end}), flush=True)
    except KeyboardInterrupt:
        print(json.dumps({"rc": "between"}), flush=True)
"""


def _reader(stream, q: Queue) -> None:
    for line in stream:
        q.put(line)
    q.put(None)


def _next(q: Queue, timeout: float) -> dict:
    line = q.get(timeout=timeout)
    assert line is not None, "the child ended"
    return json.loads(line)


def _check_kept(r: dict) -> None:
    """The message says what is on disk."""
    err, st = r["err"], r["status"]
    assert "Traceback" not in err, err
    if "no summary written" in err:
        assert st == "missing", r
    elif "the run had finished" in err:
        assert st == "ok", r
    else:
        assert st == "interrupted" and "summary.json status: interrupted" in err, r


@pytest.mark.slow
def test_signals_at_random_instants_never_crash_or_get_lost(tmp_path):
    env = dict(os.environ, OCEANGNC_POSTPROC="inline", PYTHONUNBUFFERED="1")
    proc = subprocess.Popen(
        [sys.executable, "-X", "faulthandler", "-c", CHILD, str(tmp_path / "run")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    q: Queue = Queue()
    threading.Thread(target=_reader, args=(proc.stdout, q), daemon=True).start()
    rng = random.Random(41)
    outcomes = {"run": 0, "between": 0}
    lost: list = []
    try:
        first = _next(q, 600)  # a first run unsignalled: compiles on an empty cache
        assert first["rc"] == 0 and first["status"] == "ok", first
        for i in range(SIGNALS):
            time.sleep(rng.uniform(0.0, 0.2))
            while not q.empty():  # runs that ended before this signal
                r = _next(q, 1)
                assert r["rc"] == 0 and r["status"] == "ok", r
            sig = signal.SIGINT if i % 2 == 0 else signal.SIGTERM
            t_sent = time.monotonic()
            proc.send_signal(sig)
            while True:
                try:
                    r = _next(q, 60)
                except Empty:
                    pytest.fail(f"signal {i} ({sig.name}): no run ended within 60 s")
                if r["rc"] == "between":
                    outcomes["between"] += 1
                    break
                if r["rc"] == 0:  # a run that ended normally: only before the signal could act
                    if r["t_end"] >= t_sent + 0.5:
                        lost.append((i, sig.name, r["t_end"] - t_sent))
                        break
                    continue
                assert r["rc"] == (130 if sig == signal.SIGINT else 143), r
                _check_kept(r)
                outcomes["run"] += 1
                break
            assert proc.poll() is None, f"the child ended with {proc.returncode} at signal {i}"
    finally:
        proc.kill()
        proc.wait(timeout=60)
        err = proc.stderr.read()
        print(outcomes, lost, err[-3000:])  # shown when the test fails
    assert proc.returncode == -signal.SIGKILL, err[-3000:]
    assert outcomes["run"] > SIGNALS // 2, outcomes  # most signals landed inside a run
    # A lost signal (the run ended normally 0.6-0.7 s after it: 3 in one CI run of 200) was a signal held back
    # past the command's end: restore() dropped it. It is now delivered to the handler in place then
    # (core/interrupts.py); 0 lost in 600 signals after the fix. At most one still passes, so that a rare
    # loss of another cause is seen in the output before it fails the suite
    assert len(lost) <= 1, lost
