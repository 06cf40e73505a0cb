"""Telemetry of :class:`oceangnc.mavlink.vehicle.MavlinkVehicle`: the messages of :data:`oceangnc.mavlink.protocol.TELEMETRY` at their rates."""

from __future__ import annotations

import math

from .. import __version__
from ..core.rotations import wrap_array
from ..io.geo import ned_to_latlon
from .protocol import AUTO, MAX_RATE_HZ, NAV_MODES, STICK_MODES, mavlink

M = mavlink

#: tolerance of the simulated-time schedule, s (``sim.t`` is a sum of clock ticks)
_T_EPS = 1e-6


class TelemetryMixin:
    """Heartbeats, position, attitude, HUD, status and servo outputs of the USV (and the UUV as its own system)."""

    def _due(self, name: str, now: float) -> bool:
        """Whether message ``name`` is due, and if so book it: 1 / rate has passed since it was last sent in
        simulated time (``sim.t``) or in wall time (``now``), whichever comes first.

        A stream so keeps its rate per simulated second when the simulation runs faster than real time (as
        ArduPilot SITL at SIM_SPEEDUP > 1, whose scheduler and stream timers run on the simulated clock: a
        ``.tlog`` of a 20x run, stamped with simulated time, still holds 10 Hz positions) and per wall
        second when it runs slower or stands still (after ``duration``), so ground stations keep their
        heartbeat. The simulation is advanced in stretches that end where a message falls due
        (:meth:`_ticks_to_telemetry`), so each is sent with the state of its own instant."""
        rate = self.rates[name]
        if rate <= 0:
            return False
        t = float(self.sim.t)
        by_sim = t >= self._next_sim[name] - _T_EPS
        if not by_sim and now < self._next_tx[name]:
            return False
        period = 1.0 / rate
        self._next_sim[name] = t + period
        # the wall schedule keeps its grid when it paces the stream; booked from now when simulated time did
        self._next_tx[name] = now + period if by_sim else max(self._next_tx[name] + period, now)
        return True

    def _ticks_to_telemetry(self) -> int:
        """Whole clock ticks from ``sim.t`` to the first message due in simulated time (at least 1; no limit
        while nothing is sent: no ground station and no ``.tlog``)."""
        if not self._sends_telemetry():
            return 2**62
        t = float(self.sim.t)
        nxt = min((self._next_sim[k] for k, r in self.rates.items() if r > 0), default=math.inf)
        if nxt == math.inf:
            return 2**62
        return max(1, math.ceil((nxt - t - _T_EPS) / self.tick_s)) if nxt > t else 1

    def _sends_telemetry(self) -> bool:
        return bool(self.peers or self.fixed_peers or self.tlog is not None)

    def set_rate(self, name: str, hz: float) -> None:
        """Telemetry rate of message ``name`` (Hz; 0 stops it), for every ground station (SET_MESSAGE_INTERVAL,
        REQUEST_DATA_STREAM); the next one is sent at once."""
        self.rates[name] = max(0.0, min(MAX_RATE_HZ, float(hz)))
        self._next_tx[name] = 0.0
        self._next_sim[name] = -math.inf

    def _heartbeat(self, uuv: bool = False) -> None:
        sub = self.sub2 if uuv else self.sub1
        base = M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        if self.armed:
            base |= M.MAV_MODE_FLAG_SAFETY_ARMED
        if sub is not None:  # an ArduSub system (oceangnc.mavlink.sub)
            base = sub.base_mode(self.armed)
        elif self.mode in STICK_MODES:
            base |= M.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED
        elif self.mode == AUTO:
            base |= M.MAV_MODE_FLAG_AUTO_ENABLED | M.MAV_MODE_FLAG_GUIDED_ENABLED | M.MAV_MODE_FLAG_STABILIZE_ENABLED
        elif self.mode in NAV_MODES:
            base |= M.MAV_MODE_FLAG_GUIDED_ENABLED | M.MAV_MODE_FLAG_STABILIZE_ENABLED
        if self.estop:
            status = M.MAV_STATE_EMERGENCY
        elif self.failsafe or self.stick_failsafe or (sub is not None and sub.failsafe):
            status = M.MAV_STATE_CRITICAL
        else:
            status = M.MAV_STATE_ACTIVE if self.armed else M.MAV_STATE_STANDBY
        typ = M.MAV_TYPE_SUBMARINE if uuv else self.mav_type
        self._send(
            (self.mav_uuv if uuv else self.mav).heartbeat_encode(
                typ, M.MAV_AUTOPILOT_ARDUPILOTMEGA, base, self.mode if sub is None else sub.mode, status
            ),
            uuv=uuv,
        )

    def _body(self, name: str) -> dict:
        b = self.sim.bus

        def g(k, d=0.0):
            return float(b.get(f"{name}.{k}", d))

        x, y, z = g("x"), g("y"), g("z")
        psi, u, v, w = g("psi"), g("u"), g("v"), g("w")
        vn = u * math.cos(psi) - v * math.sin(psi)
        ve = u * math.sin(psi) + v * math.cos(psi)
        return {
            "x": x,
            "y": y,
            "z": z,
            "psi": psi,
            "phi": g("phi"),
            "theta": g("theta"),
            "p": g("p"),
            "q": g("q"),
            "r": g("r"),
            "vn": vn,
            "ve": ve,
            "vd": w if name == "uuv" or self.mav_type == M.MAV_TYPE_SUBMARINE else 0.0,
            "speed": math.hypot(vn, ve),
        }

    def _global_position(self, s: dict, uuv: bool) -> None:
        c = self.cfg_mav
        lat, lon = ned_to_latlon(s["x"], s["y"], c.origin_lat_deg, c.origin_lon_deg)
        depth = s["z"] if uuv or self.mav_type == M.MAV_TYPE_SUBMARINE else 0.0  # a boat floats
        hdg = round(math.degrees(s["psi"]) % 360.0 * 100) % 36000
        tms = int(self.sim.t * 1000) & 0xFFFFFFFF

        def cl(v):
            return int(max(-32767, min(32767, round(v * 100))))

        self._send(
            (self.mav_uuv if uuv else self.mav).global_position_int_encode(
                tms,
                round(lat * 1e7),
                round(lon * 1e7),
                round((c.origin_alt_m - depth) * 1000),
                round(-depth * 1000),
                cl(s["vn"]),
                cl(s["ve"]),
                cl(s["vd"]),
                hdg,
            ),
            uuv=uuv,
        )

    def _attitude(self, s: dict, uuv: bool) -> None:
        psi = float(wrap_array(s["psi"]))
        self._send(
            (self.mav_uuv if uuv else self.mav).attitude_encode(
                int(self.sim.t * 1000) & 0xFFFFFFFF, s["phi"], s["theta"], psi, s["p"], s["q"], s["r"]
            ),
            uuv=uuv,
        )

    def _throttle(self) -> int:
        b = self.sim.bus
        usv = getattr(self.cfg, "usv", None)
        tmax = getattr(usv, "max_thrust_kgf", None)
        if tmax is None or "usv.thrust_port" not in b:
            return 0
        mean = 0.5 * (float(b["usv.thrust_port"]) + float(b.get("usv.thrust_stbd", b["usv.thrust_port"])))
        return round(min(100.0, 100.0 * abs(mean) / (tmax * 9.80665)))  # VFR_HUD.throttle is 0..100

    def _pwm(self, side: str) -> int:
        """Thruster ``side`` as servo PWM: 1500 + 400 T / T_max ahead (T / T_rev astern), us."""
        usv = getattr(self.cfg, "usv", None)
        T = float(self.sim.bus.get(f"usv.thrust_{side}", 0.0))
        hi = getattr(usv, "max_thrust_kgf", None)
        lo = getattr(usv, "max_reverse_kgf", hi)
        if not hi:
            return 1500
        full = (hi if T >= 0 else (lo or hi)) * 9.80665
        return round(1500 + 400 * max(-1.0, min(1.0, T / full)))

    def _telemetry(self, now: float) -> None:
        if not self._sends_telemetry():
            return
        c = self.cfg_mav
        usv = self._body(self.body)
        uuv = self._body("uuv") if self.has_uuv else None
        if self._due("HEARTBEAT", now):
            self._heartbeat()
            if uuv is not None:
                self._heartbeat(uuv=True)
        if self._due("SYS_STATUS", now):
            self._send_sys_status()
            if uuv is not None:
                self._send_sys_status(uuv=True)
        if self._due("GPS_RAW_INT", now):
            b = self.sim.bus
            gx, gy = float(b.get("gps.x", usv["x"])), float(b.get("gps.y", usv["y"]))
            lat, lon = ned_to_latlon(gx, gy, c.origin_lat_deg, c.origin_lon_deg)
            fix = 3 if float(b.get("gps.valid", 1.0)) > 0.5 else 0
            cog = round(math.degrees(math.atan2(usv["ve"], usv["vn"])) % 360.0 * 100) % 36000
            self._send(
                self.mav.gps_raw_int_encode(
                    int(self.sim.t * 1e6),
                    fix,
                    round(lat * 1e7),
                    round(lon * 1e7),
                    round(c.origin_alt_m * 1000),
                    100,
                    100,
                    round(usv["speed"] * 100),
                    cog,
                    12,
                )
            )
        if self._due("GLOBAL_POSITION_INT", now):
            self._global_position(usv, False)
            if uuv is not None:
                self._global_position(uuv, True)
        if self._due("ATTITUDE", now):
            self._attitude(usv, False)
            if uuv is not None:
                self._attitude(uuv, True)
        if self._due("VFR_HUD", now):
            hdg = round(math.degrees(usv["psi"])) % 360
            self._send(self.mav.vfr_hud_encode(usv["speed"], usv["speed"], hdg, self._throttle(), c.origin_alt_m, 0.0))
            if uuv is not None:
                self._send(
                    self.mav_uuv.vfr_hud_encode(
                        uuv["speed"],
                        uuv["speed"],
                        round(math.degrees(uuv["psi"])) % 360,
                        0,
                        c.origin_alt_m - uuv["z"],
                        -uuv["vd"],
                    ),
                    uuv=True,
                )
        if self._due("NAMED_VALUE_FLOAT", now):
            tms = int(self.sim.t * 1000) & 0xFFFFFFFF
            b = self.sim.bus
            if "cable.top_tension" in b:
                self._send(self.mav.named_value_float_encode(tms, b"cable_T", float(b["cable.top_tension"])))
            if uuv is not None:
                self._send(self.mav.named_value_float_encode(tms, b"uuv_depth", uuv["z"]))
            self._send(self.mav.named_value_float_encode(tms, b"rx_bad", float(self.counts["rx_bad"])))
        if self._due("SERVO_OUTPUT_RAW", now):
            self._send(
                self.mav.servo_output_raw_encode(
                    int(self.sim.t * 1e6) & 0xFFFFFFFF, 0, self._pwm("port"), 1500, self._pwm("stbd"), 1500, 0, 0, 0, 0
                )
            )
        if self._due("MISSION_CURRENT", now):
            if self.sub1 is not None:
                self.sub1.send_mission_current()
            else:
                self._send_mission_current()
            if self.sub2 is not None:
                self.sub2.send_mission_current()
        if self._due("BATTERY_STATUS", now):
            self._send_battery_status()
        if self._due("HOME_POSITION", now) and self.home is not None:
            self._send_home()

    def _send_mission_current(self) -> None:
        """MISSION_CURRENT with ``total`` = items without home (MAVLink: seq == total on the last item, 65535
        without a mission), ``mission_state`` and ``mission_mode`` (1 in AUTO, 2 suspended)."""
        n = len(self.mission)
        seq = min(self.mission_current, max(0, n - 1))
        if n <= 1:
            total, state = 65535, M.MISSION_STATE_NO_MISSION
        else:
            total = n - 1
            if self.mode == AUTO:
                state = M.MISSION_STATE_ACTIVE
            elif self.mission_current >= n:  # past the end: flown to completion
                state = M.MISSION_STATE_COMPLETE
            elif self.reached:
                state = M.MISSION_STATE_PAUSED
            else:
                state = M.MISSION_STATE_NOT_STARTED
        self._send(self.mav.mission_current_encode(seq, total, state, 1 if self.mode == AUTO else 2))

    def _sensor_bits(self) -> tuple[int, int, int]:
        """SYS_STATUS (present, enabled, healthy): the sensors the simulation provides; the geofence is
        healthy but not present (no fence: MAVProxy reports a breach when the health bit is missing); the
        pre-arm check is healthy while arming would be accepted (what MAVSDK reads as "armable")."""
        S = M
        present = (
            S.MAV_SYS_STATUS_SENSOR_GPS
            | S.MAV_SYS_STATUS_SENSOR_3D_GYRO
            | S.MAV_SYS_STATUS_SENSOR_3D_ACCEL
            | S.MAV_SYS_STATUS_SENSOR_3D_MAG
            | S.MAV_SYS_STATUS_AHRS
            | S.MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS
            | S.MAV_SYS_STATUS_SENSOR_BATTERY
            | S.MAV_SYS_STATUS_PREARM_CHECK
        )
        healthy = present | S.MAV_SYS_STATUS_GEOFENCE
        if float(self.sim.bus.get("gps.valid", 1.0)) <= 0.5:
            healthy &= ~S.MAV_SYS_STATUS_SENSOR_GPS
        if self.battery.soc < 0.1:
            healthy &= ~S.MAV_SYS_STATUS_SENSOR_BATTERY
        if self.estop or self.ended:
            healthy &= ~S.MAV_SYS_STATUS_PREARM_CHECK
        return present, present, healthy

    def _send_sys_status(self, uuv: bool = False) -> None:
        """SYS_STATUS of system 1, or with ``uuv`` of system 2 (the towed UUV: the same sensors and the one
        battery of the vehicle, so that MAVSDK and QGroundControl see it armable with a position)."""
        present, enabled, healthy = self._sensor_bits()
        n = max(1, self.counts["rx_packets"])
        drop = int(min(10000, 10000 * self.counts["rx_bad"] / n))

        def cap(v):
            return min(65535, int(v))

        b = self.battery
        self._send(
            (self.mav_uuv if uuv else self.mav).sys_status_encode(
                present,
                enabled,
                healthy,
                0,
                min(65535, round(b.voltage * 1000)),
                min(32767, round(b.current * 100)),
                round(100 * b.soc),
                drop,
                0,
                cap(self.counts["rx_bad"]),
                cap(self.counts["rx_unknown"]),
                cap(self.counts["rx_out_of_range"]),
                0,
            ),
            uuv=uuv,
        )

    def _send_battery_status(self) -> None:
        b = self.battery
        cells = [min(65534, round(b.cell_voltage() * 1000))] * min(b.cells, 10) + [65535] * max(0, 10 - b.cells)
        remaining_s = 0
        if b.current > 0.01:
            remaining_s = min(2**31 - 1, round(3600.0 * b.soc * b.capacity_ah / b.current))
        self._send(
            self.mav.battery_status_encode(
                0,
                M.MAV_BATTERY_FUNCTION_ALL,
                M.MAV_BATTERY_TYPE_LIFE,
                32767,  # temperature unknown
                cells,
                min(32767, round(b.current * 100)),
                min(2**31 - 1, round(b.charge_ah * 1000)),
                min(2**31 - 1, round(b.energy_j / 100)),  # hJ
                round(100 * b.soc),
                remaining_s,
                _charge_state(b.soc),
            )
        )

    def _send_autopilot_version(self, uuv: bool = False) -> None:
        """AUTOPILOT_VERSION: the package version as ArduPilot encodes it, the capabilities the vehicle has
        (system 2, the towed UUV: parameters and the message protocols only)."""
        sw, custom = flight_sw_version(__version__)
        if uuv:
            caps = (
                M.MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
                | M.MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_C_CAST
                | M.MAV_PROTOCOL_CAPABILITY_MISSION_INT
                | M.MAV_PROTOCOL_CAPABILITY_COMMAND_INT
                | M.MAV_PROTOCOL_CAPABILITY_FLIGHT_TERMINATION
                | M.MAV_PROTOCOL_CAPABILITY_MAVLINK2
            )
            uid = self.cfg_mav.uuv_system_id
            msg = self.mav_uuv.autopilot_version_encode(caps, sw, 0, 0, 0, custom, [0] * 8, [0] * 8, 0, 0, uid)
            self._send(msg, uuv=True)
            return
        caps = (
            M.MAV_PROTOCOL_CAPABILITY_MISSION_FLOAT
            | M.MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
            | M.MAV_PROTOCOL_CAPABILITY_MISSION_INT
            | M.MAV_PROTOCOL_CAPABILITY_COMMAND_INT
            | M.MAV_PROTOCOL_CAPABILITY_SET_POSITION_TARGET_GLOBAL_INT
            | M.MAV_PROTOCOL_CAPABILITY_FLIGHT_TERMINATION
            | M.MAV_PROTOCOL_CAPABILITY_MAVLINK2
            | M.MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_C_CAST
        )
        uid = self.cfg_mav.system_id
        self._send(self.mav.autopilot_version_encode(caps, sw, 0, 0, 0, custom, [0] * 8, [0] * 8, 0, 0, uid))

    def _send_home(self, uuv: bool = False) -> None:
        c = self.cfg_mav
        lat, lon = self._home_latlon()
        n, e = self.home if self.home is not None else (0.0, 0.0)
        self._send(
            (self.mav_uuv if uuv else self.mav).home_position_encode(
                round(lat * 1e7),
                round(lon * 1e7),
                round(c.origin_alt_m * 1000),
                float(n),
                float(e),
                0.0,
                [1, 0, 0, 0],
                0.0,
                0.0,
                0.0,
            ),
            uuv=uuv,
        )


def flight_sw_version(version: str) -> tuple[int, list[int]]:
    """ArduPilot's ``flight_sw_version`` for a package version: major << 24 | minor << 16 | patch << 8 | type,
    type (FIRMWARE_VERSION_TYPE) 255 official, 192 release candidate, 128 beta, 64 alpha, 0 development;
    and ``flight_custom_version``: the first 8 characters of a git hash in the version (``+g<hash>``), else 0."""
    import re

    m = re.match(r"(\d+)(?:\.(\d+))?(?:\.(\d+))?(.*)", version.strip())
    if m is None:
        return 0, [0] * 8
    major, minor, patch = (min(255, int(x or 0)) for x in m.group(1, 2, 3))
    rest = m.group(4).lower()
    kind = M.FIRMWARE_VERSION_TYPE_OFFICIAL
    for tag, t in (("dev", M.FIRMWARE_VERSION_TYPE_DEV), ("rc", M.FIRMWARE_VERSION_TYPE_RC),
                   ("b", M.FIRMWARE_VERSION_TYPE_BETA), ("a", M.FIRMWARE_VERSION_TYPE_ALPHA)):  # fmt: skip
        if re.match(rf"[.\-_]?{tag}\d*", rest.split("+")[0]):
            kind = t
            break
    g = re.search(r"\+g([0-9a-f]{4,})", rest)
    custom = [ord(c) for c in (g.group(1)[:8] if g else "")] + [0] * 8
    return (major << 24) | (minor << 16) | (patch << 8) | kind, custom[:8]


def _charge_state(soc: float) -> int:
    if soc >= 0.2:
        return M.MAV_BATTERY_CHARGE_STATE_OK
    if soc >= 0.1:
        return M.MAV_BATTERY_CHARGE_STATE_LOW
    return M.MAV_BATTERY_CHARGE_STATE_CRITICAL if soc > 0 else M.MAV_BATTERY_CHARGE_STATE_EMPTY
