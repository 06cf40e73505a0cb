"""Simulation core: frames and rotations, integrators, blocks and the multi-rate clock."""
