"""Frequency-domain hydrodynamics of the USV's hull (issue 29 part B).

* :mod:`.coefficients` - the coefficient file (added mass A(w), radiation damping B(w), A(inf),
  excitation force X(w, beta), hydrostatic stiffness C, rigid-body mass M, mean drift), loading,
  saving and the response amplitude operators; needs numpy only.
* :mod:`.bem` - computing them with capytaine (the optional extra ``oceangnc[hydro]``) for a
  parametric hull (a barge of 003 table 5-1's dimensions) or a mesh file, cached by the inputs' hash.
* :mod:`.radiation` - the state-space fit of the radiation memory of Cummins' equation.
* :mod:`.cli` - ``oceangnc hydro``.

All arrays are in the body frame of the USV's manoeuvring model (x forward, y starboard, z down, SNAME
order surge, sway, heave, roll, pitch, yaw), about the reference point at the waterline amidships.
"""

from .coefficients import HydroCoefficients, default_usv_coefficients, load_coefficients

__all__ = ["HydroCoefficients", "default_usv_coefficients", "load_coefficients"]
