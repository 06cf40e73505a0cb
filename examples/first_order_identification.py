"""Identify the first-order USV of document 000 from simulated sea trials, then design its autopilot.

    python examples/first_order_identification.py [out_dir]

1. ``trials``: straight runs and 10-deg turns at several speeds plus 10/10 and 20/20 zig-zags,
   generated from the table-2 model with realistic sensor noise (0.05 m/s, 0.5 deg, 0.3 deg/s);
2. the integral method (000 eq. 8-21) on every trial and the linear fits against speed (table 2),
   the same as ``oceangnc identify first-order <out_dir>/trials/log.parquet``;
3. the pole-placed heading gains (000 eq. 26-27) at 6 m/s from the *identified* coefficients, and
   the closed-loop overshoot they promise.
"""

import sys
import warnings
from pathlib import Path

import oceangnc
from oceangnc.control.pole_placement import heading_gains, predicted_overshoot
from oceangnc.identification.first_order import Columns, identify_log

out = Path(sys.argv[1] if len(sys.argv) > 1 else "runs/example-first-order")

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # the straight runs start from rest, below the table-2 range
    res = oceangnc.run("trials", out=out / "trials",
                       overrides={"noise.speed_mps": 0.05, "noise.heading_deg": 0.5, "noise.yaw_rate_degps": 0.3})

rep = identify_log(res.df, Columns(), n_mc=200)
print(rep.table())

print("\n000 table 2 vs identified (coef = a u + b):")
for name, a, b in (("K_v", 0.0004, 0.0014), ("T_v", 1.1737, -2.2474), ("K_r", -0.0113, 0.7176),
                   ("T_r", -0.1534, 2.6341)):
    f = rep.fits[name]
    print(f"  {name}: paper {a:+.4g} u {b:+.4g}   identified {f.slope:+.4g}(+-{f.slope_std:.1g}) u "
          f"{f.intercept:+.4g}(+-{f.intercept_std:.1g})")

u = 6.0
K = rep.fits["K_r"].slope * u + rep.fits["K_r"].intercept
T = rep.fits["T_r"].slope * u + rep.fits["T_r"].intercept
k1, k2 = heading_gains(K, T, zeta=0.7, wn=0.6)
print(f"\nheading PD at {u} m/s from the identified model: K1 = {k1:.3f} s, K2 = {k2:.3f} 1/s; "
      f"predicted overshoot {100 * predicted_overshoot(0.7):.1f} %")
print(f"plots: {', '.join(str(p) for p in res.plots)}")
