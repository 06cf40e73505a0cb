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
UNITS = frozenset(
    {
        "1",
        "bool",
        "str",
        "enum",
        "count",
        "s",
        "Hz",
        "1/s",
        "m",
        "m/s",
        "m/s^2",
        "m^2",
        "m^3",
        "kg",
        "kg/m",
        "kg m^2",
        "rad",
        "rad/s",
        "rad/s^2",
        "N",
        "N m",
        "N/m",
        "W",
        "J",
        "Pa",
        "V",
        "A",
        "rpm_frac",
        "K",
        # display units, only for signals whose name says so (``*_deg``, ``*_rpm``, ``*_kn``); SI stays inside
        "deg",
        "deg/s",
        "rpm",
        "kn",
    }
)


#: defaults of the environment inputs of the plants: calm water and air when no environment block runs
CALM = {"env.current_n": 0.0, "env.current_e": 0.0, "env.wind_n": 0.0, "env.wind_e": 0.0}


class WiringError(ConfigError):
    """The blocks of a simulation do not fit together (missing producer, double writer, unit mismatch)."""


def _decl(obj, attr: str) -> dict[str, str] | None:
    d = getattr(obj, attr, None)
    return None if d is None else dict(d)


def _what(p) -> str:
    return f"{'plant' if hasattr(p, 'state_names') else 'block'} '{getattr(p, 'name', repr(p))}'"


def check_units(owner: str, decl: Mapping[str, str]) -> None:
    """Refuse a declaration whose unit is not in :data:`UNITS`."""
    for sig, unit in decl.items():
        if unit not in UNITS:
            raise WiringError(
                f"{owner}: signal '{sig}' declares unknown unit '{unit}'; allowed: {', '.join(sorted(UNITS))}"
            )


def check_wiring(parts: Iterable, external: Mapping[str, str] | None = None) -> dict[str, str]:
    """Check declared signals of ``parts`` (plants and blocks); return ``{signal: unit}`` of all writers.

    Parts that declare ``inputs = None`` / ``outputs = None`` (undeclared, e.g. a quick
    :class:`~oceangnc.core.blocks.FunctionBlock`) are skipped for the side they do not declare;
    when any part leaves its outputs undeclared, a missing producer cannot be decided and is left
    to the plant's read at run time (every shipped scenario declares everything).
    Raises :class:`WiringError` naming the block and the signal.
    """
    writers: dict[str, tuple[str, str]] = {}
    for sig, unit in (external or {}).items():
        writers[sig] = ("<external>", unit)
    parts = list(parts)
    # an undeclared (legacy) writer may write anything: then a missing producer cannot be decided here
    # (the plant's read still fails at run time); double writers and units are still checked
    all_declared = True
    for p in parts:
        outs = _decl(p, "outputs")
        if outs is None:
            all_declared = False
            continue
        check_units(_what(p), outs)
        for sig, unit in outs.items():
            if sig in writers:
                raise WiringError(f"signal '{sig}' is written by two blocks: '{writers[sig][0]}' and '{p.name}'")
            writers[sig] = (p.name, unit)
    for p in parts:
        for attr, required in (("inputs", True), ("optional_inputs", False)):
            ins = _decl(p, attr)
            if not ins:
                continue
            check_units(_what(p), ins)
            for sig, unit in ins.items():
                w = writers.get(sig)
                if w is None:
                    if required and all_declared:
                        raise WiringError(
                            f"{_what(p)} reads '{sig}' ({unit}) but no block, plant or external source writes it"
                        )
                    continue
                if unit != w[1]:
                    raise WiringError(f"unit mismatch on '{sig}': '{w[0]}' writes {w[1]} but {_what(p)} reads {unit}")
    return {k: v[1] for k, v in writers.items()}


def undeclared(parts: Iterable) -> list[str]:
    """Names of the parts that do not declare their inputs or outputs (``None``): the wiring
    check cannot see them. Every shipped block and plant declares both (tests assert it)."""
    return [
        getattr(p, "name", repr(p))
        for p in parts
        if getattr(p, "inputs", None) is None or getattr(p, "outputs", None) is None
    ]
