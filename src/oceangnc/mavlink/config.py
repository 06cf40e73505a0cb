"""Settings of the MAVLink vehicle (``oceangnc mavlink --set mavlink.<key>=value``)."""

from __future__ import annotations

from pydantic import Field

from ..io.config import StrictModel


class MavlinkConfig(StrictModel):
    """Identity, geodetic origin, failsafe and limits of the MAVLink endpoint."""

    origin_lat_deg: float = Field(
        47.397742, ge=-89.9, le=89.9, description="latitude of the local NED origin (x = y = 0), deg"
    )
    origin_lon_deg: float = Field(8.545594, ge=-180, le=180, description="longitude of the local NED origin, deg")
    origin_alt_m: float = Field(0.0, ge=-1000, le=10000, description="altitude (AMSL) of the sea surface, m")
    system_id: int = Field(1, ge=1, le=250, description="MAVLink system id of the USV")
    uuv_system_id: int = Field(2, ge=1, le=250, description="MAVLink system id of the UUV (if the scenario has one)")
    gcs_timeout_s: float = Field(
        5.0,
        gt=0.05,
        le=60,
        description="GCS failsafe (ArduPilot FS_GCS_TIMEOUT): no heartbeat or message from the controlling "
        "ground station for this long in a stick mode (MANUAL, ACRO) -> HOLD, wall-clock s",
    )
    stick_timeout_s: float = Field(
        1.5,
        gt=0.05,
        le=30,
        description="stick failsafe (ArduPilot Rover FS_TIMEOUT): a MANUAL_CONTROL / RC_CHANNELS_OVERRIDE stream "
        "that was flowing in a stick mode stops for this long -> HOLD, wall-clock s",
    )
    rc_override_time_s: float = Field(
        3.0,
        gt=0.05,
        le=120,
        description="ArduPilot's RC_OVERRIDE_TIME: a MANUAL_CONTROL / RC_CHANNELS_OVERRIDE holds for this long; "
        "the stick failsafe comes when a stream stopped for this long (or FS_TIMEOUT if longer), wall-clock s",
    )
    gcs_sysid: int | None = Field(
        None,
        ge=1,
        le=255,
        description="system id of the controlling ground station (SYSID_MYGCS); default: the one whose control act "
        "(arm/disarm, mode change, mission start) was last accepted",
    )
    fs_gcs_enable: int = Field(
        1,
        ge=0,
        le=2,
        description="GCS failsafe (ArduPilot Rover FS_GCS_ENABLE): 0 off, 1 on in every mode while armed, "
        "2 on but a mission in AUTO continues",
    )
    fs_action: int = Field(
        2,
        ge=1,
        le=4,
        description="failsafe action (ArduPilot Rover FS_ACTION): 1 RTL, 2 HOLD, 3 SMART_RTL (else RTL), "
        "4 SMART_RTL (else HOLD)",
    )
    loiter_radius_m: float = Field(
        2.0, ge=0.5, le=100, description="LOITER (and arrival in GUIDED / RTL): drift this far before moving back, m"
    )
    smart_rtl_points: int = Field(
        300, ge=10, le=10000, description="SMART_RTL: breadcrumbs kept of the path flown (ArduPilot SRTL_POINTS)"
    )
    smart_rtl_accuracy_m: float = Field(
        2.0, gt=0, le=100, description="SMART_RTL: a breadcrumb every this many metres (ArduPilot SRTL_ACCURACY)"
    )
    battery_capacity_ah: float = Field(
        100.0, gt=0, le=1e5, description="battery capacity (ArduPilot BATT_CAPACITY, there in mAh), Ah"
    )
    battery_cells: int = Field(8, ge=1, le=100, description="LiFePO4 cells in series (8: 25.6 V nominal)")
    battery_r_int_ohm: float = Field(0.02, ge=0, le=10, description="battery internal resistance, ohm")
    battery_soc0: float = Field(1.0, ge=0, le=1, description="state of charge at the start, 0..1")
    thruster_power_w: float = Field(
        1344.0, ge=0, le=1e6, description="electrical power of one thruster at full forward thrust, W"
    )
    hotel_power_w: float = Field(30.0, ge=0, le=1e5, description="electrical power of everything else, W")
    max_packets_per_loop: int = Field(
        500, ge=1, le=100000, description="datagrams read per loop pass (bounds the work a flood can cause)"
    )
    mission_timeout_s: float = Field(
        3.0, gt=0, le=60, description="mission upload abandoned after this long without an item, s"
    )
    max_mission_items: int = Field(200, ge=2, le=10000, description="largest mission accepted (items)")
    peer_timeout_s: float = Field(
        10.0, gt=0, le=3600, description="a GCS address silent for this long gets no more telemetry, s"
    )
