"""Watch a run: the 3D replay page and an MCAP file for Foxglove (docs/view.md).

Runs the flagship ``combined-survey`` for 60 s, writes ``replay.html`` (open it in any browser,
offline) and, when the ``mcap`` package is installed (``pip install 'oceangnc[view]'``),
``run.mcap`` into the run folder, and prints the MCAP's channels.

    python examples/replay_and_mcap.py [--out runs/replay-example]
"""

from __future__ import annotations

import argparse

import oceangnc
from oceangnc.view.replay import write_replay


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="runs/replay-example")
    args = ap.parse_args()
    res = oceangnc.run("combined-survey", duration=60, out=args.out, plots=False, overwrite=True)
    print(f"replay page: {write_replay(res.out_dir)}")
    try:
        from mcap.reader import make_reader

        from oceangnc.view.mcap_export import export_mcap
    except ImportError:
        print("no MCAP: pip install 'oceangnc[view]'")
        return
    path = export_mcap(res.out_dir)
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    for cid, ch in sorted(summary.channels.items()):
        n = summary.statistics.channel_message_counts[cid]
        print(f"  {ch.topic:<22} {summary.schemas[ch.schema_id].name:<28} {n} messages")
    print(f"MCAP: {path} (open in Foxglove with src/oceangnc/view/static/foxglove-layout.json)")


if __name__ == "__main__":
    main()
