"""``oceangnc console [SCENARIO] [--host 127.0.0.1] [--port 8050] [--speed 1.0]``."""

from __future__ import annotations

import ipaddress


def register(subparsers) -> None:
    p = subparsers.add_parser("console", help="operator console in the browser: live simulation, joystick, "
                              "autopilot, emergency stop (http://127.0.0.1:8050)")
    p.add_argument("scenario", nargs="?", help="scenario (default: combined-survey if live, else usv-remote)")
    p.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1: this machine only)")
    p.add_argument("--port", type=int, default=8050, help="TCP port (default 8050)")
    p.add_argument("--speed", type=float, default=1.0, help="simulated seconds per wall-clock second (default 1)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a config key (repeatable)")
    p.add_argument("--out", default="runs", help="folder for the runs' logs (default runs/)")
    p.add_argument("--stream-hz", type=float, default=25.0, help="state messages per second (20-60, default 25)")
    p.set_defaults(func=_cmd_console)


def _cmd_console(args) -> int:
    from ..errors import InputError
    from ..io.config import flatten, parse_sets

    if not (0 < args.port < 65536):
        raise InputError(f"--port {args.port}: allowed range 1 <= port <= 65535")
    if not (20.0 <= args.stream_hz <= 60.0):
        raise InputError(f"--stream-hz {args.stream_hz}: allowed range 20 <= value <= 60 (Hz)")
    if args.host != "localhost":
        try:
            ipaddress.ip_address(args.host)
        except ValueError:
            raise InputError(f"--host {args.host!r}: not an IP address (use 127.0.0.1, or 0.0.0.0 for all)") from None
    try:
        from .server import main_banner, serve
        from .session import Session
    except ModuleNotFoundError as e:
        raise InputError(f"the console needs the optional package '{e.name}'; install with "
                         f"pip install 'oceangnc[console]'") from None
    overrides = flatten(parse_sets(args.set))
    session = Session(args.scenario, overrides=overrides, speed=args.speed, out_root=args.out,
                      start_on_connect=True)
    _check_port(args.host, args.port)
    serve(session, args.host, args.port, stream_hz=args.stream_hz,
          ready=lambda srv: main_banner(args.host, args.port, session))
    return 0


def _check_port(host: str, port: int) -> None:
    import socket

    from ..errors import InputError

    fam = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(fam, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind((host, port))
        except OSError as e:
            raise InputError(f"cannot listen on {host}:{port}: {e.strerror} (choose another --port)") from None
