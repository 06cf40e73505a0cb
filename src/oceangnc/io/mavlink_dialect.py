"""The MAVLink message and enum tables (pymavlink's ``ardupilotmega`` dialect, MAVLink 2), shared by the
MAVLink vehicle (:mod:`oceangnc.mavlink`) and the field-log importers (:mod:`oceangnc.io.importers`), so
that reading a ``.tlog`` does not depend on the MAVLink app (issue 39)."""

from __future__ import annotations

import os

os.environ.setdefault("MAVLINK20", "1")

from pymavlink.dialects.v20 import ardupilotmega as mavlink  # noqa: E402  (MAVLINK20 must be set first)

__all__ = ["mavlink"]
