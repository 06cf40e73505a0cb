"""Parameter sweep with seeds: how the USV's turning circle in gusty wind depends on the thrust split.

Runs 4 starboard thrust commands x 4 seeds of gusty wind (16 runs of 40 s) on a local Dask cluster
of 2 worker processes, then prints the statistics per point and writes the report plots.

    NUMBA_NUM_THREADS=1 python examples/sweep.py [OUT_DIR]

The same from the command line:

    oceangnc sweep usv-turn-wind --grid command.thrust_stbd_kgf=10,15,20,25 --seeds 4 --duration 40 \
        --set environment.wind.gust_sigma=0.5 --workers 2 --out runs/example-sweep
    oceangnc sweep-report runs/example-sweep
"""

import sys

from oceangnc.sweep import make_report, sweep


def main(out: str = "runs/example-sweep") -> None:
    res = sweep("usv-turn-wind", grid={"command.thrust_stbd_kgf": [10, 15, 20, 25]}, seeds=4, duration=40.0,
                overrides={"environment.wind.gust_sigma": 0.5}, workers=2, out=out, resume=True, progress=True)
    print(f"{len(res.executed)} runs done now, {res.skipped} already there; table: {res.out_dir / 'results.parquet'}")
    rep = make_report(res.out_dir, metrics=["usv.turn_radius_m", "usv.yaw_rate_degps", "usv.drift_speed_mps"])
    cols = ["param.command.thrust_stbd_kgf", "ok", "usv.turn_radius_m.mean", "usv.turn_radius_m.std",
            "usv.yaw_rate_degps.mean", "usv.drift_speed_mps.mean"]
    print(rep.points[cols].to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print("\n".join(str(f) for f in rep.files))


if __name__ == "__main__":  # needed: Dask starts its worker processes by re-importing this script
    main(*sys.argv[1:2])
