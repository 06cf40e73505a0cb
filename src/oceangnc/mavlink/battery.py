"""A simple battery for the MAVLink vehicle: state of charge and terminal voltage from the thrusters'
electrical power, so ground stations show a real battery and the USV's endurance becomes a result.

Numbers (our choice, documented in docs/mavlink-and-logs.md; all settable with ``--set mavlink.battery_*``):

* thrusters: the USV's two 36.2 kgf thrusters are the size of an 80 lb, 24 V trolling motor, which draws
  about 56 A at full thrust, so ``thruster_power_w`` = 24 V x 56 A = 1344 W per thruster at full forward
  thrust. Below it the power follows momentum theory for a propeller at rest, P ~ |T|^(3/2) (an actuator
  disc: P = T^(3/2) / sqrt(2 rho A)), P_i = P_max (|T_i| / T_max)^(3/2), astern on the same curve;
* hotel load (autopilot, radio, GPS) ``hotel_power_w`` = 30 W;
* pack: LiFePO4, 8 cells in series (25.6 V nominal), 100 Ah (2.56 kWh), internal resistance 20 mOhm;
  open-circuit cell voltage by state of charge (a typical LiFePO4 discharge curve at rest)

      SoC  0     0.05  0.10  0.20  0.50  0.90  1.00
      V    2.80  3.00  3.20  3.25  3.30  3.35  3.40   (per cell)

  the terminal voltage V solves V = V_oc - R P / V (current I = P / V), and the charge drawn is the
  integral of I over simulated time: dSoC/dt = -I / (3600 C).

At the cruise speed of ``usv-remote`` (0.7 m/s: d11 u = 515 N, 26 kgf per thruster) the thrusters draw
about 1.6 kW, so the pack lasts about an hour and a half. The model does not limit the thrust: an empty
pack is reported (SYS_STATUS battery unhealthy below 10 %, "Battery low" at 20 %, "Battery empty" at 0 %),
the run goes on. Thrust is sampled once per loop pass of the vehicle.
"""

from __future__ import annotations

import math

import numpy as np

_SOC = np.array([0.0, 0.05, 0.10, 0.20, 0.50, 0.90, 1.00])
_V_CELL = np.array([2.80, 3.00, 3.20, 3.25, 3.30, 3.35, 3.40])


class Battery:
    """State of charge (0..1), terminal voltage (V), current (A) and energy drawn (J) of the pack."""

    def __init__(self, capacity_ah: float, cells: int, r_int_ohm: float, soc: float = 1.0):
        self.capacity_ah = float(capacity_ah)
        self.cells = int(cells)
        self.r_int = float(r_int_ohm)
        self.soc = float(soc)
        self.current = 0.0
        self.energy_j = 0.0
        self.charge_ah = 0.0
        self.voltage = self.ocv()

    def ocv(self) -> float:
        """Open-circuit pack voltage at the present state of charge, V."""
        return self.cells * float(np.interp(self.soc, _SOC, _V_CELL))

    def cell_voltage(self) -> float:
        return self.voltage / self.cells

    def step(self, power_w: float, dt: float) -> None:
        """Draw ``power_w`` (W) for ``dt`` simulated seconds."""
        voc = self.ocv()
        disc = voc * voc - 4.0 * self.r_int * power_w
        v = 0.5 * (voc + math.sqrt(disc)) if disc > 0 else 0.5 * voc  # beyond the pack's maximum power
        i = power_w / v if v > 0 else 0.0
        self.voltage, self.current = v, i
        if dt > 0:
            self.charge_ah += i * dt / 3600.0
            self.energy_j += power_w * dt
            self.soc = max(0.0, self.soc - i * dt / (3600.0 * self.capacity_ah))


def thruster_power(thrusts_n, t_max_n: float, p_max_w: float) -> float:
    """Electrical power (W) of the thrusters at thrusts ``thrusts_n`` (N): P_max (|T| / T_max)^(3/2) each."""
    if not t_max_n > 0:
        return 0.0
    return sum(p_max_w * min(1.0, abs(float(t)) / t_max_n) ** 1.5 for t in thrusts_n)
