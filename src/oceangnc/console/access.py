"""Refused requests of the console: counted, not stored one by one, and failed token checks throttled per
peer (issue 26: 1,100 tokenless requests flushed a take-over alarm out of the event history).

* :class:`AccessLog` counts every refused request by kind (``token``, ``origin``, ``host``,
  ``throttled``) and turns them into at most one *summary* event per ``interval_s`` (the first refusal
  after a quiet interval is reported at once, the rest of the interval in one summary when it is
  over). Summaries go to their own short history on the session, never into the operators' one, and
  to the run's ``events.jsonl``.
* :class:`Throttle` gives each peer address a bucket of ``limit`` failed token checks that refills
  over ``window_s``; an empty bucket answers HTTP 429 to every wrong or missing token of that peer until
  the bucket refills. The right token always gets through (issue 41): every local user shares
  127.0.0.1, so a process sending 5 wrong tokens a second locked the operator out (0 of 30 reconnects
  with the right token, when an empty bucket refused the right token too). The throttle slows the
  failures only. That a throttled guesser still learns when it hits is harmless: the token holds 128
  random bits (:func:`oceangnc.console.server.new_token`, and the Foxglove stream's own token), 2^127
  guesses on average. No sleep: a refusal costs one dictionary look-up.
* :func:`token_refusal` is that rule, shared by the console and the Foxglove streams
  (:mod:`oceangnc.view.foxglove_ws`).
"""

from __future__ import annotations

import math
import secrets
import threading
import time
from collections import Counter


class Throttle:
    """Failed token checks per peer: ``limit`` in any ``window_s`` (a token bucket), then HTTP 429.

    At most ``max_peers`` addresses are remembered (the oldest forgotten first), so a flood from many
    addresses cannot grow the server's memory."""

    def __init__(self, limit: int = 20, window_s: float = 60.0, clock=time.monotonic, max_peers: int = 4096):
        self.limit = float(limit)
        self.rate = float(limit) / float(window_s)  # tries given back per second
        self.window_s = float(window_s)
        self.clock = clock
        self.max_peers = int(max_peers)
        self._peers: dict[str, list[float]] = {}  # peer -> [tries left, time of that count]
        self._lock = threading.Lock()

    def _left(self, entry: list[float], now: float) -> float:
        return min(self.limit, entry[0] + (now - entry[1]) * self.rate)

    def wait_s(self, peer: str) -> float:
        """0 when ``peer`` may try its token now, else the seconds until it may."""
        entry = self._peers.get(peer)
        if entry is None:
            return 0.0
        left = self._left(entry, self.clock())
        return 0.0 if left >= 1.0 else (1.0 - left) * self.window_s / self.limit

    def failed(self, peer: str) -> None:
        """``peer`` presented a missing or wrong token."""
        now = self.clock()
        with self._lock:
            entry = self._peers.pop(peer, None)
            left = self.limit if entry is None else self._left(entry, now)
            if len(self._peers) >= self.max_peers:
                self._forget(now)
            self._peers[peer] = [max(0.0, left - 1.0), now]  # re-inserted: the dict is oldest first

    def _forget(self, now: float) -> None:
        full = [p for p, e in self._peers.items() if self._left(e, now) >= self.limit]
        for p in full:
            del self._peers[p]
        while len(self._peers) >= self.max_peers:
            del self._peers[next(iter(self._peers))]


def token_refusal(throttle: Throttle, peer: str, presented: str, token: str) -> tuple[int, str, int] | None:
    """None when ``presented`` is ``token`` (compared in constant time; never throttled), else
    ``(429, message, retry-after s)`` while ``peer``'s bucket is empty, else ``(401, message, 0)`` with the
    failure counted against ``peer`` (module docstring)."""
    if secrets.compare_digest(presented.encode(), token.encode()):
        return None
    wait = throttle.wait_s(peer)
    if wait > 0.0:
        secs = math.ceil(wait)
        return 429, f"too many wrong or missing session tokens from {peer}; retry in {secs} s", secs
    throttle.failed(peer)
    return 401, "missing or wrong session token", 0


class AccessLog:
    """Refused requests counted by kind; ``emit(text)`` is called with at most one summary per
    ``interval_s`` (see the module docstring). ``total`` and ``by_kind`` count since the start."""

    EXAMPLES = 3  #: distinct examples of each kind quoted in a summary

    def __init__(self, emit, interval_s: float = 10.0, clock=time.monotonic):
        self.emit = emit
        self.interval_s = float(interval_s)
        self.clock = clock
        self.total = 0
        self.by_kind: Counter = Counter()
        self._pending: dict[str, list] = {}  # kind -> [count, its first distinct examples]
        self._t_emit = -float("inf")
        self._t_first = 0.0
        self._lock = threading.Lock()

    def refused(self, kind: str, example: str) -> None:
        """One refused request of ``kind``; ``example`` names it (``GET /api/state: <reason>``)."""
        now = self.clock()
        with self._lock:
            self.total += 1
            self.by_kind[kind] += 1
            p = self._pending.get(kind)
            if p is None:
                if not self._pending:
                    self._t_first = now
                self._pending[kind] = [1, [example]]
            else:
                p[0] += 1
                if len(p[1]) < self.EXAMPLES and example not in p[1]:
                    p[1].append(example)
            text = self._take(now) if now - self._t_emit >= self.interval_s else None
        if text:
            self.emit(text)

    def flush(self, force: bool = False) -> None:
        """Emit the pending summary when its interval is over (or now, with ``force``)."""
        if not self._pending:  # the common case, without the lock
            return
        now = self.clock()
        with self._lock:
            text = self._take(now) if self._pending and (force or now - self._t_emit >= self.interval_s) else None
        if text:
            self.emit(text)

    def _take(self, now: float) -> str:
        n = sum(c for c, _ in self._pending.values())
        span = now - self._t_first
        parts = [f"{c} x {kind} ({'; '.join(ex)})" for kind, (c, ex) in sorted(self._pending.items())]
        self._pending = {}
        self._t_emit = now
        when = f"in {span:.1f} s" if span >= 0.05 else "just now"
        return f"refused {n} request(s) {when}: " + "; ".join(parts) + f" [{self.total} refused since start]"
