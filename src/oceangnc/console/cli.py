"""``oceangnc console [SCENARIO] [--host 127.0.0.1] [--port 8050] [--speed 1.0] [--token-file F | --token T]
[--allow-remote] [--ssl-certfile F --ssl-keyfile F]``.

The session token comes from ``--token-file PATH`` (its first line), ``--token T`` (visible to every
user of the machine in ``ps``) or the environment variable ``OCEANGNC_CONSOLE_TOKEN``, else a new
random one. With a ``--host`` that is not loopback a given token must be strong (:func:`weak_token`).
"""

from __future__ import annotations

import ipaddress
import os

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
        help="address to bind (default 127.0.0.1: this machine only; any other address needs a strong "
        "token (--token-file, $OCEANGNC_CONSOLE_TOKEN, --token) or --allow-remote)",
    )
    p.add_argument("--port", type=int, default=8050, help="TCP port (default 8050)")
    add_live_options(p, SET_HELP, "folder for the runs' logs (default runs/)")
    p.add_argument("--stream-hz", type=float, default=25.0, help="state messages per second (20-60, default 25)")
    p.add_argument(
        "--token",
        help="session token the page must present (default: $OCEANGNC_CONSOLE_TOKEN, else a new random one, "
        "printed in the URL at start); every user of this machine sees it in 'ps': prefer --token-file "
        "or OCEANGNC_CONSOLE_TOKEN",
    )
    p.add_argument("--token-file", metavar="PATH", help="read the session token from the first line of PATH")
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
    given, source = _given_token(args)
    if not loop and not (given or args.allow_remote):
        raise InputError(
            f"--host {args.host}: the console would accept connections from the network; give a shared "
            f"secret (--token-file PATH, {TOKEN_ENV}, or --token TOKEN) or --allow-remote (random token) to confirm"
        )
    if given is not None and (len(given) < 8 or not given.isprintable() or " " in given):
        raise InputError(f"{source}: the token needs at least 8 printable characters without spaces")
    if given is not None and not loop:
        why = weak_token(given)
        if why:
            raise InputError(
                f"{source}: too weak a token for --host {args.host}, which the network can reach ({why}); "
                f"use {MIN_STRONG} or more random characters (python -c 'import secrets; "
                f"print(secrets.token_urlsafe(16))') or --allow-remote for a random one"
            )
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
    token = given or new_token()
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


TOKEN_ENV = "OCEANGNC_CONSOLE_TOKEN"  #: environment variable holding the session token
MIN_STRONG = 16  #: characters of a token the network may try (non-loopback --host)


def _given_token(args) -> tuple[str | None, str]:
    """The token given by ``--token-file``, ``--token`` or :data:`TOKEN_ENV` (in that order; the first
    two together are refused), and where it came from, for messages."""
    from ..errors import InputError

    if args.token_file is not None and args.token is not None:
        raise InputError("--token and --token-file: give one of them")
    if args.token_file is not None:
        src = f"--token-file {args.token_file}"
        try:
            with open(args.token_file, encoding="utf-8") as f:
                text = f.read(4096)
        except (OSError, UnicodeDecodeError) as e:
            raise InputError(f"{src}: cannot read it ({getattr(e, 'strerror', None) or e})") from None
        tok = text.splitlines()[0].strip() if text.strip() else ""
        if not tok:
            raise InputError(f"{src}: the file is empty (the token is its first line)")
        return tok, src
    if args.token is not None:
        return args.token, "--token"
    env = os.environ.get(TOKEN_ENV, "")
    if env:
        return env, TOKEN_ENV
    return None, ""


def weak_token(tok: str) -> str:
    """Why ``tok`` is too guessable for a console the network can reach, or "" when it is not: shorter
    than :data:`MIN_STRONG` characters, fewer than 8 different characters, a repeated pattern
    (``abcdabcd...``) or mostly a run of consecutive characters (``0123456789abcdef``). Keyboard walks and
    words are not caught: use a random token."""
    if len(tok) < MIN_STRONG:
        return f"{len(tok)} characters, fewer than {MIN_STRONG}"
    if len(set(tok)) < 8:
        return f"only {len(set(tok))} different characters"
    for p in range(1, len(tok) // 2 + 1):
        if all(tok[i] == tok[i % p] for i in range(len(tok))):
            return f"the {p}-character pattern {tok[:p]!r} repeated"
    steps = [ord(b) - ord(a) for a, b in zip(tok, tok[1:])]
    if max(steps.count(1), steps.count(-1)) >= 0.75 * len(steps):
        return "a run of consecutive characters"
    return ""


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
