"""The UDP link of :class:`oceangnc.mavlink.vehicle.MavlinkVehicle`: endpoints, sending to the peers, receiving."""

from __future__ import annotations

from ..errors import InputError
from .protocol import mavlink

M = mavlink


def parse_endpoint(text: str) -> tuple[str, int]:
    """``udp:HOST:PORT`` (or ``HOST:PORT``) -> (host, port); InputError otherwise."""
    s = text.strip()
    for pre in ("udpin:", "udp:", "udpout:"):
        if s.startswith(pre):
            s = s[len(pre) :]
            break
    host, _, port = s.rpartition(":")
    try:
        p = int(port)
    except ValueError:
        p = -1
    if not host or not (0 <= p <= 65535):
        raise InputError(f"endpoint {text!r}: expected udp:HOST:PORT, e.g. udp:127.0.0.1:14550")
    return host, p


class _Sender:
    """File-like object for ``MAVLink(file)``: every packed message goes to all live peers."""

    def __init__(self, vehicle):
        self.v = vehicle

    def write(self, buf: bytes) -> None:
        self.v._sendto_peers(bytes(buf))
        if self.v.tlog is not None:  # telemetry log: 8-byte big-endian time stamp (us) + the frame
            stamp = round((self.v.tlog_epoch + self.v.sim.t) * 1e6)
            self.v.tlog.write(stamp.to_bytes(8, "big") + bytes(buf))


class LinkMixin:
    """Send to every live peer (and the fixed ground stations); receive and parse what is waiting."""

    def _sendto_peers(self, buf: bytes) -> None:
        now = self.clock()
        dests = set(self.fixed_peers)
        dests.update(a for a, t in self.peers.items() if now - t <= self.cfg_mav.peer_timeout_s)
        for a in dests:
            try:
                self.sock.sendto(buf, a)
                self.counts["tx_packets"] += 1
            except OSError:
                pass

    def _send(self, msg, uuv: bool = False) -> None:
        (self.mav_uuv if uuv else self.mav).send(msg)

    def _receive(self) -> None:
        c = self.cfg_mav
        p = self._parser
        for _ in range(c.max_packets_per_loop):
            try:
                data, addr = self.sock.recvfrom(65535)
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                return
            self.counts["rx_packets"] += 1
            p.buf = bytearray()
            p.buf_index = 0
            p.expected_length = M.HEADER_LEN_V1 + 2
            p.have_prefix_error = False
            try:
                msgs = p.parse_buffer(data) or []
            except Exception:  # noqa: BLE001
                self.counts["rx_bad"] += 1
                continue
            if p.buf_len() > 0:  # a truncated message at the end of the datagram
                self.counts["rx_bad"] += 1
            good = False
            for m in msgs:
                kind = m.get_type()
                if kind == "BAD_DATA":
                    reason = str(getattr(m, "reason", ""))
                    self.counts["rx_unknown" if "unknown MAVLink message ID" in reason else "rx_bad"] += 1
                    continue
                if kind.startswith("UNKNOWN_"):  # a well-formed frame of a message id outside the dialect
                    self.counts["rx_unknown"] += 1
                    continue
                if m.get_srcSystem() in (c.system_id, c.uuv_system_id) and m.get_srcComponent() == 1:
                    continue  # our own echo
                good = True
                try:
                    self._handle(m)
                except Exception as e:  # noqa: BLE001 a message must never stop the run
                    self.counts["rx_bad"] += 1
                    self.event(f"{m.get_type()} failed: {type(e).__name__}", M.MAV_SEVERITY_WARNING)
            if good:
                self.peers[addr] = self.clock()
