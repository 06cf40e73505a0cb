"""Validation of the operator's messages: type, range and rate (pydantic models, a token bucket).

Every message from the page (or a scripted client) is one JSON object with a ``type`` field:

==============  =================================================================================
``stick``       ``surge``, ``yaw`` in [-1, 1] (ahead / starboard positive), ``source`` (gamepad,
                keyboard, touch, script); sent continuously (20 Hz) in remote mode: the link watchdog
                trips when none arrives for 1 s
``mode``        ``mode``: ``"remote"`` or ``"auto"``
``loop``        ``loop``: ``"closed"`` (stick -> speed / yaw-rate loops) or ``"open"`` (-> actuators)
``estop``       ``engaged``: true stops all thrust at once (latched), false resets the stop
``gains``       ``gains``: {name: value}; names and ranges come from the running controllers
``pause``       ``paused``: bool
``waypoints``   ``points``: 1 to 200 (north, east) points, m, each within +-100 km
``new_run``     ``scenario`` (optional name): restart with a fresh simulation and log
``ping``        ``id``: echoed back (link latency)
``control``     ``take``: true asks for control (``force``: true takes it over from the current
                operator, logged), false releases it
==============  =================================================================================

Fields are strictly typed: a number field takes a JSON number (not ``true``, not ``"0.5"``), a
boolean field takes ``true``/``false`` (not ``1``, not ``"yes"``), a string field a JSON string.
Only ``ping`` and ``control`` are accepted from a viewer; every other message needs the operator's
role (:mod:`oceangnc.console.server`).

A bad message is rejected with a one-line reason and never reaches the simulation. The size of a
message is capped (``MAX_MESSAGE_BYTES``) and each connection may send at most ``RATE_PER_S``
messages per second on average, with bursts of ``BURST`` (a token bucket).
"""

from __future__ import annotations

import json
import math
import time
from typing import Annotated, Literal, Union

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    TypeAdapter,
    ValidationError,
    field_validator,
)

MAX_MESSAGE_BYTES = 16_384
RATE_PER_S = 60.0
BURST = 120.0

Finite = Annotated[float, Field(allow_inf_nan=False)]


class _Msg(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)


class Stick(_Msg):
    type: Literal["stick"]
    surge: Finite = Field(ge=-1.0, le=1.0, description="surge stick, ahead positive, -1..1")
    yaw: Finite = Field(ge=-1.0, le=1.0, description="yaw stick, starboard positive, -1..1")
    source: Literal["gamepad", "keyboard", "touch", "script", "none"] = "script"


class Mode(_Msg):
    type: Literal["mode"]
    mode: Literal["remote", "auto"]


class Loop(_Msg):
    type: Literal["loop"]
    loop: Literal["closed", "open"]


class EStop(_Msg):
    type: Literal["estop"]
    engaged: bool


class Gains(_Msg):
    type: Literal["gains"]
    gains: dict[Annotated[str, Field(min_length=1, max_length=80)], Finite] = Field(min_length=1, max_length=50)


class Pause(_Msg):
    type: Literal["pause"]
    paused: bool


class Waypoints(_Msg):
    type: Literal["waypoints"]
    points: list[Annotated[list[Finite], Field(min_length=2, max_length=2)]] = Field(min_length=1, max_length=200)

    @field_validator("points")
    @classmethod
    def _in_range(cls, pts):
        for i, (n, e) in enumerate(pts):
            if abs(n) > 1e5 or abs(e) > 1e5:
                raise ValueError(f"point {i} ({n:g}, {e:g}) is farther than 100 km from the origin")
        return [(float(n), float(e)) for n, e in pts]


class NewRun(_Msg):
    type: Literal["new_run"]
    scenario: str | None = Field(None, min_length=1, max_length=80, pattern=r"^[a-z0-9][a-z0-9_-]*$")


class Ping(_Msg):
    type: Literal["ping"]
    id: int = Field(ge=0, le=2**53)


class Control(_Msg):
    type: Literal["control"]
    take: bool
    force: bool = False


Message = Annotated[
    Union[Stick, Mode, Loop, EStop, Gains, Pause, Waypoints, NewRun, Ping, Control], Field(discriminator="type")
]
_ADAPTER = TypeAdapter(Message)
TYPES = ("stick", "mode", "loop", "estop", "gains", "pause", "waypoints", "new_run", "ping", "control")
VIEWER_TYPES = ("ping", "control")  #: what a viewer may send


class Rejected(ValueError):
    """A message that failed validation; ``str()`` is the one-line reason sent back to the client."""


def _describe(err: ValidationError) -> str:
    e = err.errors()[0]
    loc = ".".join(str(p) for p in e["loc"][1:]) or "message"
    val = e.get("input")
    shown = f" = {val!r}" if not isinstance(val, (dict, list)) and val is not None else ""
    if len(shown) > 60:
        shown = shown[:57] + "..."
    more = f" (and {len(err.errors()) - 1} more)" if len(err.errors()) > 1 else ""
    return f"{loc}{shown}: {e['msg']}{more}"


def parse_message(text: str | bytes):
    """Validate one raw message; returns the message model or raises :class:`Rejected`."""
    if isinstance(text, bytes):
        if len(text) > MAX_MESSAGE_BYTES:
            raise Rejected(f"message too long ({len(text)} bytes > {MAX_MESSAGE_BYTES})")
        try:
            text = text.decode("utf-8")
        except UnicodeDecodeError:
            raise Rejected("message is not UTF-8 text") from None
    if len(text) > MAX_MESSAGE_BYTES:
        raise Rejected(f"message too long ({len(text)} characters > {MAX_MESSAGE_BYTES})")
    try:
        data = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as e:
        raise Rejected(f"malformed JSON: {e.msg if hasattr(e, 'msg') else e}") from None
    except ValueError as e:  # e.g. an integer literal too long to convert
        raise Rejected(f"malformed JSON: {str(e)[:80]}") from None
    if not isinstance(data, dict):
        raise Rejected(f"a message must be a JSON object, got {type(data).__name__}")
    kind = data.get("type")
    if kind not in TYPES:
        raise Rejected(f"unknown message type {kind!r}; known types: {', '.join(TYPES)}")
    try:
        return _ADAPTER.validate_python(data)
    except ValidationError as err:
        raise Rejected(f"{kind}: {_describe(err)}") from None


def check_gains(values: dict[str, float], specs: dict[str, dict]) -> None:
    """Check gain names and ranges against the running controllers' specs; raise :class:`Rejected`."""
    for name, v in values.items():
        if name not in specs:
            known = ", ".join(specs) or "none"
            raise Rejected(f"gains: unknown gain {name!r}; adjustable gains: {known}")
        s = specs[name]
        if not (math.isfinite(v) and s["min"] <= v <= s["max"]):
            raise Rejected(
                f"gains: {name} = {v:g}: allowed range {s['min']:g} <= value <= {s['max']:g} ({s.get('unit', '')})"
            )


class RateLimiter:
    """Token bucket: ``rate`` messages per second on average, bursts up to ``burst``."""

    def __init__(self, rate: float = RATE_PER_S, burst: float = BURST, clock=time.monotonic):
        self.rate = float(rate)
        self.burst = float(burst)
        self.clock = clock
        self.tokens = float(burst)
        self.t = clock()

    def allow(self) -> bool:
        """Take one token; False when the bucket is empty (the message must be rejected)."""
        now = self.clock()
        self.tokens = min(self.burst, self.tokens + (now - self.t) * self.rate)
        self.t = now
        if self.tokens >= 1.0:
            self.tokens -= 1.0
            return True
        return False
