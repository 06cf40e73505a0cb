"""Issue 41: the README tells a new user where everything is and how long the tests take; `oceangnc list`
cites the right figure of 003 for the cable (the thesis numbers two figures 2-10)."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from oceangnc.cli import main

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def test_the_readme_names_every_docs_page_and_package_folder():
    for page in sorted((ROOT / "docs").glob("*.md")):
        assert f"docs/{page.name}" in README, page.name
    for pkg in sorted((ROOT / "src" / "oceangnc").iterdir()):
        if (pkg / "__init__.py").exists():
            assert re.search(rf"\b{pkg.name}/", README), pkg.name


def test_the_readme_says_how_long_the_suite_takes_and_gives_a_quick_subset_of_declared_markers():
    assert "min on 2 cores" in README
    quick = re.search(r'python -m pytest -n 2 -m "([^"]+)"', README)
    assert quick is not None
    declared = {m.split(":")[0] for m in tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"][
        "ini_options"]["markers"]}  # fmt: skip
    used = set(re.findall(r"not (\w+)", quick.group(1)))
    assert used and used <= declared


def test_list_cites_the_cable_figure_of_p41_and_the_usv_figure_of_p25(capsys):
    """003's list of figures: "Fig. 2-10 Simulation results of turning motion of USV including current 25" and
    "Fig. 2-10 Simulation Result of Cable Motion with Current 41" (its sec. 2.2.3.3, printed so in ch. 2.3)."""
    assert main(["list"]) == 0
    lines = {ln.split()[0]: ln for ln in capsys.readouterr().out.splitlines() if ln.strip()}
    assert "fig 2-10 of p. 41" in lines["cable-current"] and "2.2.3.3" in lines["cable-current"]
    assert "fig 2-10 of p. 25" in lines["usv-turn-current"]
