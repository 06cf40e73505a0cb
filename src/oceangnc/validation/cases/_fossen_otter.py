"""The authors' simulation of the Otter USV: output of Fossen's own model, the reference of two vehicle cases.

Fossen (2023), Python Vehicle Simulator, ``otter.py`` at commit 95213c15852e91380be7d8a4c45613ab0338c40a
(2023-10-15, github.com/cybergalactic/PythonVehicleSimulator, MIT licence): the last revision with
Y_v = 0 and the Munk moment in yaw neglected, the revision ``models/vehicles/otter.toml`` follows. Its
``otter()`` (payload 25 kg at (0.05, 0, -0.35) m, rho = 1026 kg/m^3) was run with constant shaft
speeds, stepped by its own ``dynamics()`` and ``attitudeEuler()`` (forward Euler) at h = 0.02 s for
200 s from rest; at h = 0.005 s the steady values agree to 1e-4. The program is not part of oceangnc:
only its output is kept here (numbers, in SI units).
"""

#: the run, as the cases' source states it
RUN = (
    "otter() of that commit (payload 25 kg at (0.05, 0, -0.35) m, rho 1026), shaft speeds held constant "
    "(n_max = 103.931 rad/s gives k_pos n_max^2 = 119.682 N), stepped with its own dynamics() and attitudeEuler() "
    "(forward Euler) at h = 0.02 s for 200 s from rest; the same at h = 0.005 s agrees to 1e-4"
)

#: left propeller at n_max, right stopped: the steady circle read from the track after 150 s (= 2 U / r)
TURN_DIAMETER = 14.3536
#: ... and its steady state: u (m/s), v (m/s), r (rad/s)
TURN_STEADY = (1.5631, -0.3513, 0.22324)
#: ... and its track (north, east) in m every 2 s from 0 to 200 s
TURN_TRACK = (
    (0.0, 0.0),
    (0.55, 0.03),
    (2.59, 0.77),
    (4.76, 2.75),
    (5.99, 5.63),
    (5.86, 8.8),
    (4.37, 11.61),
    (1.82, 13.5),
    (-1.3, 14.11),
    (-4.38, 13.3),
    (-6.8, 11.25),
    (-8.11, 8.35),
    (-8.03, 5.17),
    (-6.58, 2.34),
    (-4.05, 0.41),
    (-0.94, -0.24),
    (2.14, 0.52),
    (4.6, 2.53),
    (5.95, 5.42),
    (5.91, 8.6),
    (4.51, 11.45),
    (2.01, 13.42),
    (-1.09, 14.11),
    (-4.19, 13.4),
    (-6.67, 11.42),
    (-8.06, 8.55),
    (-8.07, 5.38),
    (-6.71, 2.5),
    (-4.25, 0.5),
    (-1.15, -0.24),
    (1.95, 0.42),
    (4.47, 2.37),
    (5.9, 5.21),
    (5.96, 8.39),
    (4.64, 11.28),
    (2.2, 13.32),
    (-0.88, 14.11),
    (-4.0, 13.49),
    (-6.54, 11.58),
    (-8.01, 8.76),
    (-8.12, 5.58),
    (-6.84, 2.67),
    (-4.44, 0.6),
    (-1.37, -0.24),
    (1.76, 0.34),
    (4.33, 2.21),
    (5.84, 5.0),
    (6.0, 8.18),
    (4.77, 11.11),
    (2.39, 13.22),
    (-0.67, 14.1),
    (-3.8, 13.57),
    (-6.4, 11.74),
    (-7.95, 8.97),
    (-8.15, 5.79),
    (-6.97, 2.84),
    (-4.62, 0.7),
    (-1.58, -0.23),
    (1.56, 0.26),
    (4.19, 2.05),
    (5.78, 4.8),
    (6.03, 7.97),
    (4.89, 10.94),
    (2.58, 13.12),
    (-0.45, 14.08),
    (-3.6, 13.65),
    (-6.25, 11.9),
    (-7.89, 9.17),
    (-8.19, 6.0),
    (-7.09, 3.02),
    (-4.8, 0.81),
    (-1.79, -0.21),
    (1.36, 0.18),
    (4.04, 1.9),
    (5.72, 4.6),
    (6.06, 7.76),
    (5.0, 10.76),
    (2.76, 13.01),
    (-0.24, 14.06),
    (-3.4, 13.72),
    (-6.11, 12.05),
    (-7.82, 9.37),
    (-8.21, 6.21),
    (-7.2, 3.2),
    (-4.98, 0.92),
    (-2.0, -0.18),
    (1.16, 0.11),
    (3.89, 1.75),
    (5.64, 4.4),
    (6.08, 7.55),
    (5.11, 10.58),
    (2.93, 12.89),
    (-0.03, 14.03),
    (-3.2, 13.79),
    (-5.95, 12.19),
    (-7.74, 9.57),
    (-8.23, 6.43),
    (-7.31, 3.38),
    (-5.16, 1.04),
    (-2.21, -0.15),
    (0.96, 0.05),
)

#: both propellers at n_max / sqrt 2 (59.841 N each): the steady surge speed (m/s)
HALF_THRUST_SPEED = 1.6388
