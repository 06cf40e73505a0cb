"""The validation registry (`oceangnc validate`): every case of the report is a test here, a parameter change
that breaks a published figure makes its case fail with the numbers, the report opens in Chromium, and the
time-step advisor (`oceangnc check`) reports limits and refuses a step above them."""

from __future__ import annotations

import math
import os
import shutil
from pathlib import Path

import pytest

from oceangnc.cli import main
from oceangnc.models.usv import USVConfig
from oceangnc.validation import Runner, run_case, select
from oceangnc.validation.cases import CASES
from oceangnc.validation.check import check


@pytest.fixture(scope="module")
def runner():
    r = Runner()
    yield r
    r.close()


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_case(case, runner):
    """The same registry as the report: a case passes here iff it passes there. A documented deviation must
    still deviate (strict: if it starts to pass, docs/combined-vehicle.md and the registry need updating)."""
    o = run_case(case, runner)
    assert o.status != "error", o.error
    m = o.measured
    assert math.isfinite(m.value)
    msg = (
        f"{case.id}: {case.quantity} = {m.value:.6g} {case.unit}, accepted {o.lo:.6g} … {o.hi:.6g} "
        f"(published {case.published_text}; {case.source})"
    )
    if case.deviation:
        assert o.status == "deviation", "now reproduced: " + msg
    else:
        assert o.status == "pass", msg


def test_registry_is_complete_and_well_formed():
    """Every case names a seed file or a physical law, a tolerance and its reason; the seeds' figures the
    issue lists are all there."""
    ids = [c.id for c in CASES]
    assert len(ids) == len(set(ids))
    for c in CASES:
        assert c.source and c.quantity and c.why and c.published_text, c.id
        assert c.check[0] in ("abs", "rel", "max", "min", "range"), c.id
        assert ("_" in c.source and ".txt" in c.source) or c.id.startswith("physics-"), c.id
    for want in (
        "003-fig2-7",
        "003-fig2-8",
        "003-fig2-9",
        "003-fig2-10",
        "003-fig4-2",
        "003-fig4-4",
        "003-fig4-6",
        "003-fig4-7",
        "003-fig4-14",
        "003-fig4-15",
        "003-ch6.2",
        "000-table2",
        "000-fig17",
        "000-fig18",
        "000-fig21",
        "000-figs25-26",
        "001-figs8-10",
        "002-table5.2",
        "002-table5.3",
        "physics-cable-statics",
        "physics-energy-conservation",
        "physics-energy-dissipation",
        "physics-rk4-order",
        "physics-uuv-steady-speed",
        "physics-lyapunov-vdot",
    ):
        assert any(i.startswith(want) for i in ids), want
    assert [c.id for c in select(CASES, "003-fig2-8*")] == ["003-fig2-8-turn-radius", "003-fig2-8-yaw-rate"]


def test_changed_parameter_breaks_the_matching_case_with_numbers(tmp_path, capsys):
    """Doubling the USV's surge damping d11 halves the straight-run speed of 003 fig 2-7: the case fails,
    the exit code is 1 and the message gives the value, the accepted range and the source."""
    d11 = 2.0 * USVConfig().d11
    code = main(
        ["validate", "--only", "003-fig2-7", "--set", f"usv.d11={d11}", "--out", str(tmp_path), "--no-plots", "--quiet"]
    )
    out = capsys.readouterr().out
    assert code == 1
    assert "FAIL 003-fig2-7-usv-speed: steady surge speed = 0.4" in out
    assert "accepted 0.75 … 0.85" in out and "003_486f48bcab6eec1d.txt fig 2-7" in out
    md = (tmp_path / "report.md").read_text()
    assert "`usv.d11=" in md and "FAIL" in md
    # the defaults pass the same case
    assert main(["validate", "--only", "003-fig2-7", "--out", str(tmp_path / "ok"), "--no-plots", "--quiet"]) == 0


def test_unknown_pattern_is_an_input_error(tmp_path, capsys):
    assert main(["validate", "--only", "no-such-case", "--out", str(tmp_path)]) == 2
    assert "matches no validation case" in capsys.readouterr().err


def test_check_reports_limits_accuracy_and_rates():
    """cable-current: the axial limit of each integrator (the split one is larger, and equal to the limit
    from the linearised right-hand side), the step in use below it, a fourth-order-small step-halving difference, and the 10 Hz environment loop."""
    rep = check("cable-current", horizon=2.0)
    assert not rep.refused
    lim = {i: v for _, i, v, _ in rep.limits}
    assert {"rk4", "rk4-split", "rk4 (linearised)", "euler (linearised)"} <= set(lim)
    assert lim["rk4-split"] > lim["rk4"]
    # the split step integrates the right-hand side without the axial dampers: its linearisation at the
    # settled state gives the same limit as the analytic chain
    assert lim["rk4 (linearised)"] == pytest.approx(lim["rk4-split"], rel=0.05)
    assert lim["euler (linearised)"] < 1e-3 * lim["rk4-split"]  # near-undamped axial modes: Euler is useless
    used = [v for _, _, v, u in rep.limits if u]
    assert len(used) == 1 and rep.dt <= used[0]
    assert rep.accuracy and max(d for _, d, _, u in rep.accuracy if u == "m") < 1e-3
    assert any(n == "current" and abs(1.0 / p - 10.0) < 1e-9 for n, p in rep.loops)
    txt = rep.text()
    assert "stability limits" in txt and "expected accuracy" in txt and "Hz" in txt


def test_check_refuses_a_step_above_the_limit(capsys):
    assert main(["check", "cable-current", "--set", "sim.dt=0.01"]) == 2
    out = capsys.readouterr().out
    assert "REFUSED: dt = 0.01 s is above the stability limit" in out and "use sim.dt <=" in out


def _chromium() -> str | None:
    for cand in (
        os.environ.get("CHROMIUM_PATH"),
        shutil.which("chromium"),
        "/usr/lib/chromium/chromium",
        shutil.which("chromium-browser"),
    ):
        if cand and Path(cand).exists():
            return cand
    return None


@pytest.mark.browser
def test_report_opens_in_chromium(tmp_path):
    """A small report (two cases) opens in headless Chromium: the summary and the table render and every
    plot image loads; the screenshot is written."""
    exe = _chromium()
    if exe is None:
        pytest.skip("no Chromium binary (install Debian's 'chromium' or set CHROMIUM_PATH)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    assert main(["validate", "--only", "003-fig2-8*", "--out", str(tmp_path), "--quiet"]) == 0
    page_url = (tmp_path / "report.html").resolve().as_uri()
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, headless=True)
        page = browser.new_page(viewport={"width": 1200, "height": 900})
        page.goto(page_url)
        assert "2 cases: 2 pass" in page.inner_text("#summary")
        assert page.locator("#cases tr").count() == 3
        page.wait_for_function("Array.from(document.images).every(i => i.complete)", timeout=30_000)
        widths = page.evaluate("Array.from(document.images).map(i => i.naturalWidth)")
        assert len(widths) == 2 and all(w > 100 for w in widths)
        page.screenshot(path=str(tmp_path / "report.png"), full_page=True)
        browser.close()
    assert (tmp_path / "report.png").stat().st_size > 10_000


def test_flagship_geometry_and_the_dragged_uuv():
    """The flagship explanation (docs/combined-vehicle.md): a 0.23 m rise on a 3 m taut cable needs a 1.15 m
    horizontal offset; the survey's 0.5 m offset gives 0.04 m on the 3.23 m hanging length; and the UUV dragged
    with its thrusters at zero trails > 1.2 m behind, rises above 2.85 m and pitches less than 4 deg, 003's
    depth and pitch, while the controlled UUV stays near 3.19 m."""
    from oceangnc.validation.flagship import depth_rise, offset_for_rise, run_uncontrolled

    assert offset_for_rise(0.23, 3.0) == pytest.approx(1.15, abs=0.01)
    assert depth_rise(0.5, 3.233) == pytest.approx(0.039, abs=0.002)
    m = run_uncontrolled()
    assert m["rel_mean_m"] > 1.2
    assert m["depth_final_m"] < 2.85
    assert abs(m["pitch_late_deg"]) < 4.0
