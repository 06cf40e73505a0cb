"""A minimal ground station on plain pymavlink for the MAVLink tests (127.0.0.1 only, bounded waits)."""

from __future__ import annotations

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
