"""The package version (one place; read by the caches and the MAVLink version message)."""

__version__ = "0.1.0"
