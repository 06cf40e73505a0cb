"""Telemetry of :class:`oceangnc.mavlink.vehicle.MavlinkVehicle`: the messages of :data:`oceangnc.mavlink.protocol.TELEMETRY` at their rates."""

from __future__ import annotations

import math

from .geo import ned_to_latlon
from .protocol import AUTO, NAV_MODES, STICK_MODES, TELEMETRY, mavlink

M = mavlink


class TelemetryMixin:
    """Heartbeats, position, attitude, HUD, status and servo outputs of the USV (and the UUV as its own system)."""

    def _due(self, name: str, now: float) -> bool:
        if now >= self._next_tx[name]:
            rate = TELEMETRY[name][0]
            self._next_tx[name] = max(self._next_tx[name] + 1.0 / rate, now)
            return True
        return False

    def _heartbeat(self, uuv: bool = False) -> None:
        base = M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        if self.armed:
            base |= M.MAV_MODE_FLAG_SAFETY_ARMED
        if self.mode in STICK_MODES:
            base |= M.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED
        elif self.mode == AUTO:
            base |= M.MAV_MODE_FLAG_AUTO_ENABLED | M.MAV_MODE_FLAG_GUIDED_ENABLED | M.MAV_MODE_FLAG_STABILIZE_ENABLED
        elif self.mode in NAV_MODES:
            base |= M.MAV_MODE_FLAG_GUIDED_ENABLED | M.MAV_MODE_FLAG_STABILIZE_ENABLED
        if self.estop:
            status = M.MAV_STATE_EMERGENCY
        elif self.failsafe:
            status = M.MAV_STATE_CRITICAL
        else:
            status = M.MAV_STATE_ACTIVE if self.armed else M.MAV_STATE_STANDBY
        typ = M.MAV_TYPE_SUBMARINE if uuv else M.MAV_TYPE_SURFACE_BOAT
        self._send(
            (self.mav_uuv if uuv else self.mav).heartbeat_encode(
                typ, M.MAV_AUTOPILOT_ARDUPILOTMEGA, base, self.mode, status
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
            "vd": w if name == "uuv" else 0.0,
            "speed": math.hypot(vn, ve),
        }

    def _global_position(self, s: dict, uuv: bool) -> None:
        c = self.cfg_mav
        lat, lon = ned_to_latlon(s["x"], s["y"], c.origin_lat_deg, c.origin_lon_deg)
        depth = s["z"] if uuv else 0.0
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
        psi = math.atan2(math.sin(s["psi"]), math.cos(s["psi"]))
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
        if not self.peers and not self.fixed_peers and self.tlog is None:
            return
        c = self.cfg_mav
        usv = self._body("usv")
        uuv = self._body("uuv") if self.has_uuv else None
        if self._due("HEARTBEAT", now):
            self._heartbeat()
            if uuv is not None:
                self._heartbeat(uuv=True)
        if self._due("SYS_STATUS", now):
            sensors = (
                M.MAV_SYS_STATUS_SENSOR_GPS | M.MAV_SYS_STATUS_SENSOR_3D_GYRO | M.MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS
            )
            gps_ok = float(self.sim.bus.get("gps.valid", 1.0)) > 0.5
            healthy = sensors if gps_ok else sensors & ~M.MAV_SYS_STATUS_SENSOR_GPS
            n = max(1, self.counts["rx_packets"])
            drop = int(min(10000, 10000 * self.counts["rx_bad"] / n))

            def cap(v):
                return min(65535, int(v))

            self._send(
                self.mav.sys_status_encode(
                    sensors,
                    sensors,
                    healthy,
                    0,
                    0,
                    -1,
                    -1,
                    drop,
                    0,
                    cap(self.counts["rx_bad"]),
                    cap(self.counts["rx_unknown"]),
                    cap(self.counts["rx_out_of_range"]),
                    0,
                )
            )
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
            self._send(self.mav.mission_current_encode(min(self.mission_current, max(0, len(self.mission) - 1))))

    def _send_autopilot_version(self) -> None:
        caps = (
            M.MAV_PROTOCOL_CAPABILITY_MISSION_INT
            | M.MAV_PROTOCOL_CAPABILITY_MAVLINK2
            | M.MAV_PROTOCOL_CAPABILITY_COMMAND_INT
        )
        self._send(self.mav.autopilot_version_encode(caps, 0, 0, 0, 0, [0] * 8, [0] * 8, [0] * 8, 0, 0, 0))

    def _send_home(self) -> None:
        c = self.cfg_mav
        lat, lon = self._home_latlon()
        n, e = self.home if self.home is not None else (0.0, 0.0)
        self._send(
            self.mav.home_position_encode(
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
            )
        )
