"""Every script in ``examples/`` and every ```python block in ``README.md`` and ``docs/*.md`` runs.

A broken example or doc snippet fails the suite (issue 17). Each runs in a fresh interpreter in a
temporary folder with ``OCEANGNC_MAX_DURATION`` capping every scenario's simulated time (a smoke
run: the code paths, not the figures) and the Agg matplotlib backend. The python blocks of one
document run in order as one script (later blocks may use names of earlier ones); a block preceded
by ``<!-- no-test -->`` is skipped.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
MAX_DURATION = "2"
#: examples that need something a test run does not have, with the reason
SKIP = {
    "console_client.py": "a client of a running console server (the protocol is tested in test_console.py)",
    "console_screenshot.py": "drives Chromium through Playwright against a running console (test_console_browser.py)",
}
#: extra command-line arguments (keep outputs inside the temporary folder)
ARGS = {"berthing.py": ["--runs", "1", "--out", "out", "--img", "img"]}

BLOCK = re.compile(r"(<!--\s*no-test[^>]*-->\s*\n)?```python\n(.*?)```", re.S)


def _env() -> dict:
    env = dict(os.environ)
    env["OCEANGNC_MAX_DURATION"] = MAX_DURATION
    env["MPLBACKEND"] = "Agg"
    # examples/ holds mygnc, the user package of docs/developing.md
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), str(ROOT / "examples"), env.get("PYTHONPATH", "")])
    return env


def _run(argv: list[str], cwd: Path) -> None:
    p = subprocess.run([sys.executable, *argv], cwd=cwd, env=_env(), capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, f"{' '.join(argv)} failed ({p.returncode}):\n{p.stdout[-2000:]}\n{p.stderr[-4000:]}"


def doc_blocks(text: str) -> list[str]:
    """The ```python blocks of a markdown text, without those opted out by ``<!-- no-test -->``."""
    return [m.group(2) for m in BLOCK.finditer(text) if not m.group(1)]


def test_doc_block_parser_honours_opt_out():
    text = "a\n```python\nx = 1\n```\n<!-- no-test -->\n```python\nraise SystemExit(3)\n```\n```python\ny = x\n```\n"
    assert doc_blocks(text) == ["x = 1\n", "y = x\n"]


#: examples run in a fresh interpreter (Dask starts worker processes that re-import ``__main__``)
SUBPROCESS = {"sweep.py"}


@pytest.mark.slow
@pytest.mark.parametrize("script", EXAMPLES, ids=[p.name for p in EXAMPLES])
def test_example_runs(script, tmp_path, monkeypatch):
    """Each example as ``__main__`` (in this interpreter, which saves the imports, unless it must not)."""
    if script.name in SKIP:
        pytest.skip(SKIP[script.name])
    args = ARGS.get(script.name, [str(tmp_path / "out")] if "sys.argv" in script.read_text() else [])
    if script.name in SUBPROCESS:
        _run([str(script), *args], tmp_path)
        return
    import runpy

    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.setenv("OCEANGNC_MAX_DURATION", MAX_DURATION)
    monkeypatch.setattr(sys, "argv", [str(script), *args])
    monkeypatch.chdir(tmp_path)
    try:
        runpy.run_path(str(script), run_name="__main__")
    except SystemExit as e:  # argparse or an explicit exit
        assert e.code in (0, None), f"{script.name} exited with {e.code}"
    finally:
        import matplotlib.pyplot as plt

        plt.close("all")


DOCS_WITH_CODE = [d for d in DOCS if doc_blocks(d.read_text())]


@pytest.mark.slow
@pytest.mark.parametrize("doc", DOCS_WITH_CODE, ids=[d.name for d in DOCS_WITH_CODE])
def test_doc_code_blocks_run(doc, tmp_path):
    code = "\n".join(doc_blocks(doc.read_text()))
    # the guard lets a block start worker processes (Dask re-imports __main__) without re-running itself
    script = tmp_path / f"{doc.stem}_blocks.py"
    script.write_text(
        f"CODE = {code!r}\nif __name__ == '__main__':\n"
        f"    exec(compile(CODE, {str(doc)!r}, 'exec'), {{'__name__': 'doc_example'}})\n"
    )
    _run([str(script)], tmp_path)
