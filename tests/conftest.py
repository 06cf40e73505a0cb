"""Test-session setup: subprocesses (the CLI, servers, examples) import this checkout's ``src`` too,
so a clone or a git worktree sharing a virtual environment with another checkout tests its own code."""

import os
from pathlib import Path

_SRC = str(Path(__file__).resolve().parents[1] / "src")
os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (_SRC, os.environ.get("PYTHONPATH", "")) if p)
