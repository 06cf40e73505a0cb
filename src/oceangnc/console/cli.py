"""``oceangnc console [SCENARIO] [--host 127.0.0.1] [--port 8050] [--speed 1.0] [--token T] [--allow-remote]
[--ssl-certfile F --ssl-keyfile F]``."""

from __future__ import annotations

import ipaddress

from ..cli_options import SET_HELP, add_live_options, needs_package, set_overrides


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "console",
        help="operator console in the browser: live simulation, joystick, "
        "autopilot, emergency stop (http://127.0.0.1:8050)",
    )
    p.add_argument("scenario", nargs="?", help="scenario (default: combined-survey if live, else usv-remote)")
    p.add_argument(
        "--host",
        default="127.0.0.1",
        help="address to bind (default 127.0.0.1: this machine only; "
        "any other address needs --token or --allow-remote)",
    )
    p.add_argument("--port", type=int, default=8050, help="TCP port (default 8050)")
    add_live_options(p, SET_HELP, "folder for the runs' logs (default runs/)")
    p.add_argument("--stream-hz", type=float, default=25.0, help="state messages per second (20-60, default 25)")
    p.add_argument(
        "--token", help="session token the page must present (default: a new random one, printed in the URL at start)"
    )
    p.add_argument("--allow-remote", action="store_true", help="allow a non-loopback --host with a random token")
    p.add_argument("--ssl-certfile", help="PEM certificate: serve HTTPS/WSS (with --ssl-keyfile)")
    p.add_argument("--ssl-keyfile", help="PEM private key of --ssl-certfile")
    p.add_argument("--no-warmup", action="store_true", help="skip compiling the scenario before listening")
    p.set_defaults(func=_cmd_console)


def _cmd_console(args) -> int:
    from ..errors import InputError

    if not (0 < args.port < 65536):
        raise InputError(f"--port {args.port}: allowed range 1 <= port <= 65535")
    if not (20.0 <= args.stream_hz <= 60.0):
        raise InputError(f"--stream-hz {args.stream_hz}: allowed range 20 <= value <= 60 (Hz)")
    if args.host != "localhost":
        try:
            ipaddress.ip_address(args.host)
        except ValueError:
            raise InputError(f"--host {args.host!r}: not an IP address (use 127.0.0.1, or 0.0.0.0 for all)") from None
    loop = args.host == "localhost"
    if not loop:
        loop = ipaddress.ip_address(args.host).is_loopback
    if not loop and not (args.token or args.allow_remote):
        raise InputError(
            f"--host {args.host}: the console would accept connections from the network; "
            f"give --token TOKEN (shared secret) or --allow-remote (random token) to confirm"
        )
    if args.token is not None and (len(args.token) < 8 or not args.token.isprintable() or " " in args.token):
        raise InputError("--token: at least 8 printable characters without spaces")
    if bool(args.ssl_certfile) != bool(args.ssl_keyfile):
        raise InputError("--ssl-certfile and --ssl-keyfile go together")
    for f in (args.ssl_certfile, args.ssl_keyfile):
        if f:
            from pathlib import Path

            if not Path(f).is_file():
                raise InputError(f"TLS file not found: {f}")
    try:
        from .server import main_banner, new_token, serve
        from .session import Session
    except ModuleNotFoundError as e:
        raise InputError(needs_package("the console", e.name, "console")) from None
    overrides = set_overrides(args)
    session = Session(args.scenario, overrides=overrides, speed=args.speed, out_root=args.out, start_on_connect=True)
    _check_port(args.host, args.port)
    if not args.no_warmup:
        import sys

        print(f"oceangnc console: compiling and warming up {session.scenario.name} ...", file=sys.stderr, flush=True)
        took = session.warmup()
        print(f"oceangnc console: ready after {took:.1f} s", file=sys.stderr, flush=True)
    token = args.token or new_token()
    tls = bool(args.ssl_certfile)
    serve(
        session,
        args.host,
        args.port,
        stream_hz=args.stream_hz,
        token=token,
        ssl_certfile=args.ssl_certfile,
        ssl_keyfile=args.ssl_keyfile,
        ready=lambda srv, app: main_banner(args.host, args.port, session, token, tls),
    )
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
