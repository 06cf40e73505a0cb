"""``report.md`` and ``report.html`` of a validation run, one PNG per case.

Each case's plot shows the project's curve(s) with the published value: the tolerance band on the
y axis (when the quantity is what the curve plots) or the published points as markers, labelled
with their source. No figure of the documents is copied; the published numbers are the printed
ones quoted in the registry.
"""

from __future__ import annotations

import datetime as _dt
import html
import math
from collections.abc import Sequence
from pathlib import Path

from . import KINDS, Outcome

#: what a passing case of each class shows (the report's class table)
KIND_MEANING = {
    "prediction": "a published result reproduced with no parameter fitted to it (the only reproductions)",
    "calibration": "a fit holds: the named parameters were fitted or chosen to it (not a reproduction)",
    "round-trip": "the method's algebra on data the project generated itself (not a reproduction)",
    "reference": "another program running the same model equations gives the same result (the implementation, "
    "not the physics)",
    "analytic": "code verification: the simulation agrees with a closed-form or independent solution of its own "
    "equations and coefficients",
    "law": "a physical law holds whatever the coefficients",
}

STATUS_MARK = {"pass": "PASS", "fail": "FAIL", "deviation": "DEVIATION (documented)", "error": "ERROR"}


def _fmt(v) -> str:
    if v is None:
        return "–"
    if isinstance(v, float):
        if not math.isfinite(v):
            return "–" if math.isnan(v) else ("∞" if v > 0 else "−∞")
        if v != 0 and (abs(v) < 1e-3 or abs(v) >= 1e5):
            return f"{v:.3e}"
        return f"{v:.4g}"
    return str(v)


def plot_case(o: Outcome, path: Path) -> Path | None:
    """The project's curve(s) beside the published value (band or points)."""
    m = o.measured
    if m is None or (not m.series and not m.ref_points):
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.6, 3.3))
    for label, x, y in m.series:
        ax.plot(x, y, lw=1.3, label=f"oceangnc: {label}")
    for label, x, y in m.ref_points:
        ax.plot(x, y, "o", ms=7, mfc="none", mew=2, color="C3", label=label)
    if m.band and o.published is not None and math.isfinite(o.lo) and math.isfinite(o.hi):
        ax.axhspan(o.lo, o.hi, color="C2", alpha=0.15, label=f"published {_fmt(o.published)} {o.case.tolerance_text()}")
        ax.axhline(o.published, color="C2", lw=1)
    if o.case.id.startswith("physics-rk4"):
        ax.set_xscale("log")
        ax.set_yscale("log")
    ax.set_xlabel(m.xlabel)
    ax.set_ylabel(m.ylabel)
    ax.set_title(f"{o.case.id}: {STATUS_MARK[o.status]}", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6.5, loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=72)
    plt.close(fig)
    return path


def summary_counts(outcomes: Sequence[Outcome]) -> dict:
    out = {k: 0 for k in STATUS_MARK}
    for o in outcomes:
        out[o.status] += 1
    return out


def class_counts(outcomes: Sequence[Outcome]) -> dict:
    """class -> {"cases", "pass", "fail", "deviation", "error"} in :data:`KINDS` order (classes with no case
    included, with zeros)."""
    out = {k: {"cases": 0, **{st: 0 for st in STATUS_MARK}} for k in KINDS}
    for o in outcomes:
        out[o.case.kind]["cases"] += 1
        out[o.case.kind][o.status] += 1
    return out


def _plural(n: int, word: str) -> str:
    return f"{n} {word}" + ("" if n == 1 else ("es" if word.endswith("ch") else "s"))


def evidence_text(outcomes: Sequence[Outcome]) -> str:
    """One sentence: how many cases of each class, and how many predictions pass (the reproductions)."""
    k = class_counts(outcomes)
    p = k["prediction"]
    parts = [
        f"{_plural(p['cases'], 'prediction')} ({p['pass']} pass, {p['deviation']} documented deviation(s), "
        f"{p['fail'] + p['error']} fail/error)",
        _plural(k["calibration"]["cases"], "calibration target"),
        _plural(k["round-trip"]["cases"], "round trip"),
        _plural(k["reference"]["cases"], "reference-implementation comparison"),
        _plural(k["analytic"]["cases"], "analytic check") + " (code verification)",
        _plural(k["law"]["cases"], "physical law"),
    ]
    return (
        "By class: " + ", ".join(parts) + f". Reproduced published results: {p['pass']} (passing predictions only; "
        "a calibration target or a round trip passes by construction and is not counted)"
    )


def write_report(
    outcomes: Sequence[Outcome],
    out_dir: Path,
    overrides: dict | None = None,
    flagship_md: str = "",
    plots: bool = True,
    wall_s: float | None = None,
) -> tuple[Path, Path]:
    """Write ``report.md``, ``report.html`` and ``img/<case>.png`` into ``out_dir``."""
    out_dir = Path(out_dir)
    (out_dir / "img").mkdir(parents=True, exist_ok=True)
    imgs = {}
    if plots:
        for o in outcomes:
            p = plot_case(o, out_dir / "img" / f"{o.case.id}.png")
            if p is not None:
                imgs[o.case.id] = f"img/{p.name}"
    c = summary_counts(outcomes)
    stamp = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
    head = (
        f"{len(outcomes)} cases: {c['pass']} pass, {c['fail']} fail, {c['deviation']} documented deviation(s), "
        f"{c['error']} error(s)"
    )
    over = ", ".join(f"`{k}={v}`" for k, v in (overrides or {}).items()) or "none (the scenarios' defaults)"
    evidence = evidence_text(outcomes)
    kc = class_counts(outcomes)
    class_rows = [
        (KINDS[k], v["cases"], v["pass"], v["fail"], v["deviation"], v["error"], KIND_MEANING[k]) for k, v in kc.items()
    ]

    md = [
        "# oceangnc validation report",
        "",
        f"Generated {stamp} by `oceangnc validate`" + (f" in {wall_s:.0f} s" if wall_s else "") + ".",
        f"Overrides: {over}.",
        "",
        f"**{head}.**",
        "",
        f"{evidence}.",
        "",
        "| class | cases | pass | fail | deviation | error | what a pass shows |",
        "|---|---|---|---|---|---|---|",
        *[f"| {a} | {b} | {c_} | {d} | {e} | {f} | {g} |" for a, b, c_, d, e, f, g in class_rows],
        "",
        "A case passes when the project's value lies within the tolerance of the published (or analytic) value. "
        "DEVIATION marks a documented disagreement with the source that the physics does not remove; it does not "
        "fail the run. Sources are the seed documents by file name and figure/table/equation.",
        "",
        "| case | class | source | quantity | published | tolerance | oceangnc | status |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for o in outcomes:
        k = o.case
        val = "–" if o.measured is None else _fmt(o.measured.value)
        pub = _fmt(o.published) if o.published is not None else k.published_text
        md.append(
            f"| [{k.id}](#{k.id}) | {KINDS[k.kind]}{', qualitative' if k.qualitative else ''} | {k.source} | {k.quantity} ({k.unit}) | {pub} | {k.tolerance_text()} | "
            f"{val} | {STATUS_MARK[o.status]} |"
        )
    if flagship_md:
        md += ["", flagship_md]
    md += ["", "## Cases", ""]
    for o in outcomes:
        k = o.case
        md += [
            f"### {k.id}",
            "",
            f"**{k.title}.** Source: {k.source}. Quantity: {k.quantity} ({k.unit}).",
            "",
            f"- class: {k.class_text()}",
            f"- published: {k.published_text}" + (f" = {_fmt(o.published)}" if o.published is not None else ""),
            f"- tolerance: {k.tolerance_text()} (accepted range {_fmt(o.lo)} … {_fmt(o.hi)}); why: {k.why}",
            f"- oceangnc: {'–' if o.measured is None else _fmt(o.measured.value)} → **{STATUS_MARK[o.status]}** "
            f"({o.wall_s:.1f} s)",
        ]
        if o.measured is not None and o.measured.note:
            md.append(f"- {o.measured.note}")
        if o.error:
            md.append(f"- error: `{o.error}`")
        if k.deviation:
            md.append(f"- documented deviation: {k.deviation}")
        if k.id in imgs:
            md += ["", f"![{k.id}]({imgs[k.id]})"]
        md.append("")
    md_path = out_dir / "report.md"
    md_path.write_text("\n".join(md) + "\n", encoding="utf-8")

    # HTML (self-contained apart from the PNGs next to it)
    colors = {"pass": "#1a7f37", "fail": "#cf222e", "deviation": "#9a6700", "error": "#cf222e"}
    rows = []
    for o in outcomes:
        k = o.case
        val = "–" if o.measured is None else _fmt(o.measured.value)
        pub = _fmt(o.published) if o.published is not None else k.published_text
        rows.append(
            f"<tr><td><a href='#{k.id}'>{html.escape(k.id)}</a></td>"
            f"<td>{html.escape(KINDS[k.kind] + (', qualitative' if k.qualitative else ''))}</td>"
            f"<td>{html.escape(k.source)}</td>"
            f"<td>{html.escape(k.quantity)} ({html.escape(k.unit)})</td><td>{html.escape(pub)}</td>"
            f"<td>{html.escape(k.tolerance_text())}</td><td>{html.escape(val)}</td>"
            f"<td class='st' style='color:{colors[o.status]}'>{STATUS_MARK[o.status]}</td></tr>"
        )
    sections = []
    for o in outcomes:
        k = o.case
        items = [
            f"<li>class: {html.escape(k.class_text())}</li>",
            f"<li>published: {html.escape(k.published_text)}"
            + (f" = {html.escape(_fmt(o.published))}" if o.published is not None else "")
            + "</li>",
            f"<li>tolerance: {html.escape(k.tolerance_text())} (accepted {html.escape(_fmt(o.lo))} … "
            f"{html.escape(_fmt(o.hi))}); why: {html.escape(k.why)}</li>",
            f"<li>oceangnc: {html.escape('–' if o.measured is None else _fmt(o.measured.value))} → "
            f"<b style='color:{colors[o.status]}'>{STATUS_MARK[o.status]}</b> ({o.wall_s:.1f} s)</li>",
        ]
        if o.measured is not None and o.measured.note:
            items.append(f"<li>{html.escape(o.measured.note)}</li>")
        if o.error:
            items.append(f"<li>error: <code>{html.escape(o.error)}</code></li>")
        if k.deviation:
            items.append(f"<li>documented deviation: {html.escape(k.deviation)}</li>")
        img = f"<img src='{imgs[k.id]}' alt='{k.id}'>" if k.id in imgs else ""
        sections.append(
            f"<section id='{k.id}'><h3>{html.escape(k.id)}</h3><p><b>{html.escape(k.title)}.</b> "
            f"Source: {html.escape(k.source)}.</p><ul>{''.join(items)}</ul>{img}</section>"
        )
    flag_html = ""
    if flagship_md:
        flag_html = (
            "<div class='flag'>"
            + "".join(
                f"<p>{html.escape(p)}</p>" for p in flagship_md.split("\n\n") if p.strip() and not p.startswith("![")
            )
            + (
                "<img src='flagship_sweep.png' alt='flagship sweep'>"
                if (out_dir / "flagship_sweep.png").exists()
                else ""
            )
            + "</div>"
        )
    page = f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>oceangnc validation report</title>
<style>
body{{font-family:system-ui,sans-serif;margin:2em auto;max-width:1100px;color:#1f2328}}
table{{border-collapse:collapse;font-size:13px}}td,th{{border:1px solid #d0d7de;padding:3px 6px;vertical-align:top}}
th{{background:#f6f8fa}}.st{{font-weight:bold;white-space:nowrap}}section{{border-top:1px solid #d0d7de;margin-top:1em}}
img{{max-width:560px}}.flag{{background:#fff8c5;padding:0.5em 1em;border-radius:6px}}.flag img{{max-width:100%}}
</style></head><body>
<h1>oceangnc validation report</h1>
<p>Generated {stamp} by <code>oceangnc validate</code>{f" in {wall_s:.0f} s" if wall_s else ""}. Overrides:
{html.escape(over)}.</p>
<p id="summary"><b>{html.escape(head)}.</b></p>
<p id="evidence">{html.escape(evidence)}.</p>
<table id="classes"><tr><th>class</th><th>cases</th><th>pass</th><th>fail</th><th>deviation</th><th>error</th>
<th>what a pass shows</th></tr>
{"".join("<tr>" + "".join(f"<td>{html.escape(str(x))}</td>" for x in row) + "</tr>" for row in class_rows)}
</table>
<table id="cases"><tr><th>case</th><th>class</th><th>source</th><th>quantity</th><th>published</th><th>tolerance</th>
<th>oceangnc</th><th>status</th></tr>
{"".join(rows)}
</table>
{flag_html}
<h2>Cases</h2>
{"".join(sections)}
</body></html>
"""
    html_path = out_dir / "report.html"
    html_path.write_text(page, encoding="utf-8")
    return md_path, html_path
