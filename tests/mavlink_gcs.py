"""A minimal ground station on plain pymavlink for the MAVLink tests (127.0.0.1 only, bounded waits)."""

from __future__ import annotations

import contextlib
import socket
import time

from oceangnc.mavlink.protocol import mavlink as M


class GCS:
    """UDP client of the vehicle: sends as system 255 / component 190 (MAVProxy's ids)."""

    def __init__(self, address):
        self.address = address
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.02)
        gcs = self

        class _W:
            def write(self, b):
                gcs.sock.sendto(bytes(b), gcs.address)

        self.mav = M.MAVLink(_W(), srcSystem=255, srcComponent=190)
        self.parser = M.MAVLink(None)
        self.parser.robust_parsing = True
        self.received: list = []
        self.heartbeat_hz = 10.0
        self._next_hb = 0.0
        self.send_heartbeats = True

    def raw(self, data: bytes) -> None:
        self.sock.sendto(data, self.address)

    def pump(self, seconds: float, until=None, stick=None):
        """Receive for up to ``seconds`` wall s (heartbeats at ``heartbeat_hz``; ``stick`` = (x, r) sent
        as MANUAL_CONTROL at 20 Hz); returns the first message satisfying ``until`` or None."""
        t_end = time.monotonic() + seconds
        next_stick = 0.0
        while time.monotonic() < t_end:
            now = time.monotonic()
            if self.send_heartbeats and now >= self._next_hb:
                self.mav.heartbeat_send(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0)
                self._next_hb = now + 1.0 / self.heartbeat_hz
            if stick is not None and now >= next_stick:
                self.mav.manual_control_send(1, int(stick[0]), 0, 0, int(stick[1]), 0)
                self._t_last_stick = now
                next_stick = now + 0.05
            try:
                data, _ = self.sock.recvfrom(65535)
            except (TimeoutError, BlockingIOError):
                continue
            for m in self.parser.parse_buffer(data) or []:
                if m.get_type() == "BAD_DATA":
                    continue
                m._t_rx = time.monotonic()
                self.received.append(m)
                if until is not None and until(m):
                    return m
        return None

    def wait(self, kind: str, seconds: float = 5.0, cond=lambda m: True, sysid: int = 1):
        m = self.pump(seconds, until=lambda m: m.get_type() == kind and m.get_srcSystem() == sysid and cond(m))
        assert m is not None, f"no {kind} within {seconds} s"
        return m

    def ack(self, command: int, seconds: float = 3.0):
        return self.wait("COMMAND_ACK", seconds, lambda m: m.command == command)

    def close(self) -> None:
        self.sock.close()


def upload_mission(g: GCS, pts, lat0: float, lon0: float, seconds: float = 3.0) -> None:
    """Mission upload as every ground station does it: MISSION_COUNT, then one MISSION_ITEM_INT per
    MISSION_REQUEST_INT; ``pts`` are (north, east) m about (lat0, lon0), the first one home (item 0)."""
    from oceangnc.io.geo import ned_to_latlon

    g.mav.mission_count_send(1, 1, len(pts), 0)
    for seq, (n, e) in enumerate(pts):
        req = g.wait("MISSION_REQUEST_INT", seconds, lambda m, s=seq: m.seq == s)
        lat, lon = ned_to_latlon(n, e, lat0, lon0)
        frame = M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT if seq else M.MAV_FRAME_GLOBAL_INT
        g.mav.mission_item_int_send(
            1, 1, req.seq, frame, M.MAV_CMD_NAV_WAYPOINT, 0, 1, 0, 0, 0, 0, round(lat * 1e7), round(lon * 1e7), 0.0, 0
        )
    ack = g.wait("MISSION_ACK", seconds)
    assert ack.type == M.MAV_MISSION_ACCEPTED, ack


def qgc_set_mode(g: GCS, custom_mode: int, seconds: float = 3.0) -> None:
    """QGroundControl's Vehicle::setFlightMode: SET_MODE with CUSTOM_MODE_ENABLED (and the armed flag as the
    vehicle last reported it), then it waits for a HEARTBEAT showing the mode (up to 3 tries)."""
    armed = any(
        m.get_type() == "HEARTBEAT" and m.get_srcSystem() == 1 and m.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED
        for m in g.received[-20:]
    )
    base = M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED | (M.MAV_MODE_FLAG_SAFETY_ARMED if armed else 0)
    for _ in range(3):
        g.mav.set_mode_send(1, base, custom_mode)
        if g.pump(seconds, until=lambda m: m.get_type() == "HEARTBEAT" and m.get_srcSystem() == 1
                  and m.custom_mode == custom_mode) is not None:  # fmt: skip
            return
    raise AssertionError(f"vehicle failed to change to mode {custom_mode}")


def qgc_connect(g: GCS, seconds: float = 3.0) -> dict:
    """QGroundControl's initial connect sequence for an ArduPilot vehicle (InitialConnectStateMachine and
    APMFirmwarePlugin): AUTOPILOT_VERSION by REQUEST_MESSAGE, the protocol version, component information,
    the stream rates (REQUEST_DATA_STREAM), the parameters (PARAM_REQUEST_LIST), the mission, fence and rally
    lists, the home position. Every command must get a COMMAND_ACK. Returns what was learnt."""
    out: dict = {"acks": {}}
    g.wait("HEARTBEAT", seconds)

    def cmd(command, *p):
        p = list(p) + [0.0] * (7 - len(p))
        g.mav.command_long_send(1, 1, command, 0, *p)
        out["acks"][(command, p[0])] = g.ack(command, seconds).result

    cmd(M.MAV_CMD_REQUEST_MESSAGE, M.MAVLINK_MSG_ID_AUTOPILOT_VERSION)
    out["version"] = g.wait("AUTOPILOT_VERSION", seconds)
    cmd(M.MAV_CMD_REQUEST_PROTOCOL_VERSION, 1)
    cmd(M.MAV_CMD_REQUEST_MESSAGE, 395)  # COMPONENT_INFORMATION (QGC then falls back to its own metadata)
    for stream, hz in ((M.MAV_DATA_STREAM_RAW_SENSORS, 2), (M.MAV_DATA_STREAM_EXTENDED_STATUS, 2),
                       (M.MAV_DATA_STREAM_RC_CHANNELS, 2), (M.MAV_DATA_STREAM_POSITION, 3),
                       (M.MAV_DATA_STREAM_EXTRA1, 10), (M.MAV_DATA_STREAM_EXTRA2, 10),
                       (M.MAV_DATA_STREAM_EXTRA3, 3)):  # fmt: skip
        g.mav.request_data_stream_send(1, 1, stream, hz, 1)
    g.mav.param_request_list_send(1, 1)
    first = g.wait("PARAM_VALUE", seconds)
    params = {first.param_index: first}
    while len(params) < first.param_count:
        m = g.wait("PARAM_VALUE", seconds)
        params[m.param_index] = m
    out["params"] = {(m.param_id if isinstance(m.param_id, str) else m.param_id.decode()): m.param_value
                     for m in params.values()}  # fmt: skip
    for mission_type in (M.MAV_MISSION_TYPE_MISSION, M.MAV_MISSION_TYPE_FENCE, M.MAV_MISSION_TYPE_RALLY):
        g.mav.mission_request_list_send(1, 1, mission_type)
        out[f"count{mission_type}"] = g.wait("MISSION_COUNT", seconds, lambda m, t=mission_type: m.mission_type == t)
        if out[f"count{mission_type}"].count == 0:
            continue
        for seq in range(out[f"count{mission_type}"].count):
            g.mav.mission_request_int_send(1, 1, seq, mission_type)
            g.wait("MISSION_ITEM_INT", seconds, lambda m, s=seq: m.seq == s)
        g.mav.mission_ack_send(1, 1, M.MAV_MISSION_ACCEPTED, mission_type)
    cmd(M.MAV_CMD_REQUEST_MESSAGE, M.MAVLINK_MSG_ID_HOME_POSITION)
    out["home"] = g.wait("HOME_POSITION", seconds)
    return out


def qgc_start_mission(g: GCS, seconds: float = 3.0) -> None:
    """QGroundControl's Start Mission on a disarmed ArduPilot ground vehicle (APMFirmwarePlugin::startMission):
    switch to GUIDED, arm (and wait for the armed HEARTBEAT), then MAV_CMD_MISSION_START."""
    qgc_set_mode(g, 15, seconds)  # GUIDED: "Unable to start mission: Vehicle failed to change to Guided mode"
    g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM, seconds).result == M.MAV_RESULT_ACCEPTED
    g.wait("HEARTBEAT", seconds, lambda m: m.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED)
    g.mav.command_long_send(1, 1, M.MAV_CMD_MISSION_START, 0, 0, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_MISSION_START, seconds).result == M.MAV_RESULT_ACCEPTED


def mavsdk_system(vehicle, seconds: float = 10.0):
    """MAVSDK as a ground station (the ``mavsdk`` wheel's bundled core) connected to ``vehicle`` on
    127.0.0.1; returns ``(sdk, system)``: the ``Mavsdk`` object (keep it alive while the system is used) and
    the discovered autopilot (asserted found within ``seconds``)."""
    from mavsdk import ComponentType, Configuration, Mavsdk

    sdk = Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION))
    sdk.add_any_connection(f"udpout://127.0.0.1:{vehicle.address[1]}")
    system = sdk.first_autopilot(seconds)
    assert system is not None, "MAVSDK found no autopilot"
    return sdk, system


@contextlib.contextmanager
def served(scenario: str = "usv-remote", *, out_root=None, **kw):
    """Yield ``(vehicle, gcs)``: a :class:`~oceangnc.mavlink.vehicle.MavlinkVehicle` serving ``scenario`` on a
    free UDP port of 127.0.0.1 (``kw``: its ``speed``, ``mav`` overrides...) and a :class:`GCS` client of it;
    both stopped at the end."""
    from oceangnc.mavlink.vehicle import MavlinkVehicle

    v = MavlinkVehicle(scenario, listen="udp:127.0.0.1:0", out_root=out_root, **kw)
    v.start()
    g = GCS(v.address)
    try:
        yield v, g
    finally:
        g.close()
        v.stop()


def wait_for(cond, seconds: float, step: float = 0.01) -> bool:
    """Poll ``cond()`` every ``step`` s for at most ``seconds`` s; its last value."""
    t_end = time.monotonic() + seconds
    while time.monotonic() < t_end:
        if cond():
            return True
        time.sleep(step)
    return bool(cond())


class MAVProxy:
    """MAVProxy (``mavproxy.py``) as a subprocess on the vehicle at 127.0.0.1:``port``, scripted through its
    command line on stdin; what it prints is read by a thread and kept in ``seen`` as (time, line)."""

    def __init__(self, mavproxy: str, port: int, *args: str, cwd=None):
        import queue
        import subprocess
        import sys
        import threading

        cmd = [sys.executable, mavproxy, f"--master=udpout:127.0.0.1:{port}", "--no-state", "--target-system=1", *args]
        self.proc = subprocess.Popen(
            cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, bufsize=1, cwd=cwd
        )
        self.lines: queue.Queue = queue.Queue()
        self.seen: list[tuple[float, str]] = []
        threading.Thread(target=lambda: [self.lines.put(ln) for ln in self.proc.stdout], daemon=True).start()

    def _next(self, timeout: float) -> str | None:
        import queue

        try:
            ln = self.lines.get(timeout=timeout)
        except queue.Empty:
            return None
        self.seen.append((time.monotonic(), ln))
        return ln

    def expect(self, text: str, timeout: float) -> float:
        """Wait (bounded) for a printed line containing ``text``; the time it was read."""
        t_end = time.monotonic() + timeout
        while time.monotonic() < t_end:
            ln = self._next(0.1)
            if ln is not None and text in ln:
                return time.monotonic()
        raise AssertionError(f"MAVProxy did not print {text!r} within {timeout} s; output:\n{self.output(30)}")

    def collect(self, seconds: float) -> None:
        """Keep what it prints for ``seconds`` s."""
        t_end = time.monotonic() + seconds
        while time.monotonic() < t_end:
            self._next(0.1)

    def output(self, last: int | None = None) -> str:
        return "".join(s for _, s in (self.seen[-last:] if last else self.seen))

    def send(self, line: str) -> None:
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()

    def close(self) -> None:
        self.proc.kill()
        self.proc.wait(10)
