"""USV open-loop trials of document 003 (figs 2-7 to 2-10), scripted from Python.

Runs the turning circle in currents from four directions and prints how the circle drifts.
"""

import oceangnc

for direction in (0, 45, 90, 180):
    res = oceangnc.run("usv-turn-current", duration=60, plots=False,
                       overrides={"environment.current.direction_deg": direction,
                                  "environment.current.speed": 0.1},
                       out=f"runs/example-usv-current-{direction}")
    s = res.summary
    print(f"current toward {direction:3d} deg: radius {s['usv.turn_radius_m']:.2f} m, "
          f"yaw rate {s['usv.yaw_rate_degps']:.1f} deg/s, centre drifts {s['usv.drift_speed_mps']:.3f} m/s "
          f"toward {s['usv.drift_direction_deg']:.0f} deg")

# the log is a Parquet table: one row per sample, columns like usv.x, usv.psi, usv.thrust_port
df = res.df
print(df[["t", "usv.x", "usv.y", "usv.psi", "usv.thrust_port"]].tail(3))
