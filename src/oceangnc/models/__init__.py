"""Vehicle, cable and actuator models (continuous-time right-hand sides, compiled with numba)."""
