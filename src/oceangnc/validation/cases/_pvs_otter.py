"""Fossen's current Otter, run unmodified: the reference numbers of the ``vehicle-otter-pvs-*`` cases.

Python Vehicle Simulator (github.com/cybergalactic/PythonVehicleSimulator, MIT licence) at commit
c717e073d7a839dcb5956cf20c595132f1fa249a (2025-05-13; ``otter.py`` last changed by 61a8f41, 2024-03-11, which
restored Y_v = -M_22 / T_sway and the Munk moment in yaw). Its ``otter()`` was stepped by its own ``dynamics()``
and ``attitudeEuler()`` (forward Euler, h = 0.02 s, as its ``mainLoop.simulate``) for 200 s from rest at
constant shaft speeds, fractions of its n_max = 103.931 rad/s. The recipe is
``docs/validation/reference/pvs_otter.py``, its output ``docs/validation/reference/pvs_otter.json`` (run
2026-11-28; ``tests/test_otter_pvs.py`` checks that these numbers are that file's). The program is not part
of oceangnc: only its output is kept here (SI units).
"""

COMMIT = "c717e073d7a839dcb5956cf20c595132f1fa249a"
RUN = (
    "Fossen's Python Vehicle Simulator at c717e07 (2025-05-13), otter() unmodified, shaft speeds held "
    "constant, its own dynamics() and attitudeEuler() (forward Euler, h = 0.02 s) for 200 s from rest "
    "(recipe docs/validation/reference/pvs_otter.py)"
)
N_MAX = 103.93086427398005  #: rad/s: sqrt(0.5 x 24.4 x 9.81 / k_pos)

#: (port, starboard) fraction of n_max -> steady u (m/s), v (m/s), r (rad/s), speed U (m/s), radius U / |r| (m)
STEADY = {
    (0.5, 0.5): (0.859077633549018, 0.0, 0.0, 0.859077633549018, None),
    (0.75, 0.75): (1.8346056451992103, 0.0, 0.0, 1.8346056451992103, None),
    (1.0, 1.0): (3.2197401395018352, 0.0, 0.0, 3.2197401395018352, None),
    (1.0, 0.5): (1.9066128482406624, -0.21587273214569702, 0.29598978890990335, 1.9187948273748339, 6.482638588451096),
    (1.0, 0.0): (1.534061595558189, -0.18139707568310184, 0.3078621764000028, 1.5447491310995833, 5.01766455744308),
}
