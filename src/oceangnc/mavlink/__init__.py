"""MAVLink: a live scenario as a vehicle for real ground stations (``oceangnc mavlink``).

See :mod:`oceangnc.mavlink.vehicle` and ``docs/mavlink-and-logs.md``.
"""
