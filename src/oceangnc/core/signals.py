"""Declared signals and the wiring check that :class:`~oceangnc.core.clock.Simulation` runs when built.

Every block and plant declares what it reads and writes as ``{signal name: unit}``:

* ``inputs``: signals the block needs; some block or plant (or the simulation's ``external``
  signals, e.g. console commands) must write each of them;
* ``optional_inputs``: signals read with a documented default when nobody writes them (a console
  mode, a joystick axis, ``_estop``);
* ``outputs``: signals the block writes every time it fires.

Units are SI strings from :data:`UNITS` (``"m"``, ``"m/s"``, ``"rad"``, ``"N"``, ``"1"`` for a
dimensionless number, ``"bool"``, ``"str"`` ...). :func:`check_wiring` rejects, with a
:class:`WiringError` naming the block and the signal: an input that nothing produces, two writers
of one signal, and a unit mismatch between a writer and a reader.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from ..errors import ConfigError

#: Units a signal may declare (SI; angles in rad; ``"1"`` dimensionless; ``"bool"``/``"str"``/``"enum"`` flags).
UNITS = frozenset({
    "1", "bool", "str", "enum", "count", "s", "Hz",
    "m", "m/s", "m/s^2", "m^2", "m^3", "kg", "kg/m", "kg m^2",
    "rad", "rad/s", "rad/s^2",
    "N", "N m", "N/m", "W", "J", "Pa", "V", "A", "rpm_frac", "K",
})


class WiringError(ConfigError):
    """The blocks of a simulation do not fit together (missing producer, double writer, unit mismatch)."""


def _decl(obj, attr: str) -> dict[str, str] | None:
    d = getattr(obj, attr, None)
    return None if d is None else dict(d)


def check_units(owner: str, decl: Mapping[str, str]) -> None:
    """Refuse a declaration whose unit is not in :data:`UNITS`."""
    for sig, unit in decl.items():
        if unit not in UNITS:
            raise WiringError(f"{owner}: signal '{sig}' declares unknown unit '{unit}'; "
                              f"allowed: {', '.join(sorted(UNITS))}")


def check_wiring(parts: Iterable, external: Mapping[str, str] | None = None) -> dict[str, str]:
    """Check declared signals of ``parts`` (plants and blocks); return ``{signal: unit}`` of all writers.

    Parts that declare ``inputs = None`` / ``outputs = None`` (undeclared, e.g. a quick
    :class:`~oceangnc.core.blocks.FunctionBlock`) are skipped for the side they do not declare.
    Raises :class:`WiringError` naming the block and the signal.
    """
    writers: dict[str, tuple[str, str]] = {}
    for sig, unit in (external or {}).items():
        writers[sig] = ("<external>", unit)
    parts = list(parts)
    for p in parts:
        outs = _decl(p, "outputs")
        if outs is None:
            continue
        check_units(f"block '{p.name}'", outs)
        for sig, unit in outs.items():
            if sig in writers:
                raise WiringError(f"signal '{sig}' is written by two blocks: '{writers[sig][0]}' and '{p.name}'")
            writers[sig] = (p.name, unit)
    for p in parts:
        for attr, required in (("inputs", True), ("optional_inputs", False)):
            ins = _decl(p, attr)
            if not ins:
                continue
            check_units(f"block '{p.name}'", ins)
            for sig, unit in ins.items():
                w = writers.get(sig)
                if w is None:
                    if required:
                        raise WiringError(f"block '{p.name}' reads '{sig}' ({unit}) but no block, plant or "
                                          f"external source writes it")
                    continue
                if unit != w[1]:
                    raise WiringError(f"unit mismatch on '{sig}': '{w[0]}' writes {w[1]} but block "
                                      f"'{p.name}' reads {unit}")
    return {k: v[1] for k, v in writers.items()}
