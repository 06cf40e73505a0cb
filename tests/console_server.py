"""A real ``oceangnc console SCENARIO`` server in a subprocess on 127.0.0.1, for the browser, 3D-view and
soak tests: started on a free port with the token in OCEANGNC_CONSOLE_TOKEN, waited for until
``/api/state`` answers (bounded), stopped at the end."""

from __future__ import annotations

import contextlib
import os
import socket
import subprocess
import sys
import tempfile
import time

import httpx
import pytest


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def console_server(out, token: str, start_timeout_s: float, scenario: str = "usv-remote"):
    """Yield ``(port, proc)`` of a console serving ``scenario`` with runs under ``out``; the test fails
    with the server's output if it exits, or after ``start_timeout_s`` s if it never answers."""
    port = free_port()
    # the token through the environment, as docs/console.md advises (--token shows in ps)
    env = dict(os.environ, NUMBA_NUM_THREADS="1", PYTHONUNBUFFERED="1", OCEANGNC_CONSOLE_TOKEN=token)
    cmd = [sys.executable, "-m", "oceangnc.cli", "console", scenario, "--port", str(port)]
    output = tempfile.TemporaryFile(mode="w+")  # not a pipe: a chatty server must never block on it
    proc = subprocess.Popen([*cmd, "--out", str(out)], env=env, stdout=output, stderr=subprocess.STDOUT, text=True)
    try:
        url = f"http://127.0.0.1:{port}"
        deadline = time.monotonic() + start_timeout_s
        while True:
            if proc.poll() is not None:
                output.seek(0)
                pytest.fail(f"console server exited: {output.read()}")
            try:
                if httpx.get(url + "/api/state", params={"token": token}, timeout=2).status_code == 200:
                    break
            except httpx.HTTPError:
                pass
            if time.monotonic() > deadline:
                pytest.fail(f"console server did not start within {start_timeout_s:g} s")
            time.sleep(0.3)
        yield port, proc
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=20)
        output.close()
