"""Test-session setup: subprocesses (the CLI, servers, examples) import this checkout's ``src`` too,
so a clone or a git worktree sharing a virtual environment with another checkout tests its own code."""

import os
from pathlib import Path

_SRC = str(Path(__file__).resolve().parents[1] / "src")
os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (_SRC, os.environ.get("PYTHONPATH", "")) if p)


def pytest_addoption(parser):
    parser.addoption(
        "--quick",
        action="store_true",
        help="the quick subset: the first test of every test module that is neither slow nor a browser test "
        "(every module of the suite touched once; README 'How long the tests take')",
    )


def pytest_collection_modifyitems(config, items):
    """``--quick``: keep, per test module, its first collected test not marked slow or browser."""
    if not config.getoption("--quick"):
        return
    keep, seen = [], set()
    for item in items:
        if item.get_closest_marker("slow") or item.get_closest_marker("browser"):
            continue
        module = item.nodeid.split("::", 1)[0]
        if module not in seen:
            seen.add(module)
            keep.append(item)
    chosen = set(map(id, keep))
    config.hook.pytest_deselected(items=[i for i in items if id(i) not in chosen])
    items[:] = keep
