"""``oceangnc export RUN --mcap [--out FILE]``, ``oceangnc view RUN [--out FILE] [--serve | --foxglove]``
and ``oceangnc view --console URL --foxglove``.

Both import nothing heavy at registration (the ``mcap`` package only when exporting): a default
install without ``oceangnc[view]`` still lists them, and ``export`` then says in one line what to
install (exit 2).
"""

from __future__ import annotations

import sys

MCAP_HINT = "error: MCAP export needs the optional package 'mcap': install oceangnc[view]"


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "export",
        help="export a run folder for other tools: --mcap (Foxglove, Lichtblick, ROS 2 tools)",
        description="Write a run folder's log as an MCAP file: vehicle poses, a 3D scene of the vehicles and "
        "the cable, GPS fixes and every logged signal, with Foxglove's well-known JSON schemas (docs/view.md).",
    )
    p.add_argument("run", help="run folder (holding log.parquet)")
    p.add_argument("--mcap", action="store_true", required=True, help="write MCAP (the one format so far)")
    p.add_argument("--out", help="file to write (default RUN/run.mcap)")
    p.set_defaults(func=_cmd_export)

    p = subparsers.add_parser(
        "view",
        help="3D replay of a run folder in the browser (writes RUN/replay.html; --serve on 127.0.0.1)",
        description="Write a self-contained 3D replay page of a run folder (vehicles, cable coloured by tension, "
        "trails, route, seabed, sea surface, time-series panels; docs/view.md), or serve it on 127.0.0.1.",
    )
    p.add_argument("run", nargs="?", help="run folder (holding log.parquet)")
    p.add_argument("--out", help="HTML file to write (default RUN/replay.html)")
    p.add_argument("--serve", action="store_true", help="serve the page on 127.0.0.1 instead of only writing it")
    p.add_argument(
        "--foxglove",
        action="store_true",
        help="stream the run to Foxglove/Lichtblick over the Foxglove WebSocket protocol on 127.0.0.1 "
        "(the MCAP export's channels, in time; needs oceangnc[console])",
    )
    p.add_argument(
        "--port", type=int, help="port of --serve (default 8060) or --foxglove (default 8765); 0: any free port"
    )
    p.add_argument(
        "--console",
        metavar="URL",
        help="--foxglove of a running 'oceangnc console' instead of a run folder: its URL with the token "
        "(as it prints it, http://127.0.0.1:8050/?token=...); read as a viewer",
    )
    p.add_argument("--speed", type=float, default=1.0, help="--foxglove: run seconds per wall second (default 1)")
    p.add_argument("--once", action="store_true", help="--foxglove: stop at the end instead of starting again")
    p.add_argument(
        "--allow-origin",
        action="append",
        default=[],
        metavar="URL",
        help="--foxglove: a browser origin to accept besides the Foxglove web app and pages of this machine",
    )
    p.add_argument("--open", action="store_true", help="open the page in the default web browser")
    p.set_defaults(func=_cmd_view)


def export_mcap_cli(run_dir, out=None) -> int:
    """Export and print the path; the one-line hint and exit code 2 when ``mcap`` is missing."""
    from .mcap_export import MissingMcap, export_mcap

    try:
        path = export_mcap(run_dir, out)
    except MissingMcap:
        print(MCAP_HINT, file=sys.stderr)
        return 2
    print(f"wrote {path}")
    return 0


def _cmd_export(args) -> int:
    warn_gaps(args.run)
    return export_mcap_cli(args.run, args.out)


def warn_gaps(run) -> None:
    """Say on stderr, one line per gap, which rows and time span of a run's log a damaged or missing
    part leaves out of an export or page (:func:`oceangnc.io.log_read.log_gaps`)."""
    from pathlib import Path

    from ..io.log_read import log_gaps

    for g in log_gaps(Path(run)):
        print(f"warning: {g}", file=sys.stderr)


def _port(port: int | None, default: int) -> int:
    from ..errors import InputError

    port = default if port is None else port
    if not 0 <= port <= 65535:
        raise InputError(f"--port {port}: out of range; allowed 0 (any free port) to 65535")
    return port


def _serving(fn, shown: int, /, *a, **kw) -> int:
    """Run a server; a port that cannot be bound (busy, privileged) is a one-line InputError."""
    import errno

    from ..errors import InputError

    try:
        return fn(*a, **kw)
    except OSError as e:
        if e.errno in (errno.EADDRINUSE, errno.EACCES, errno.EADDRNOTAVAIL, errno.EPERM):
            raise InputError(f"--port {shown}: cannot listen on it ({e.strerror}); give another port or 0") from None
        raise


def _cmd_view(args) -> int:
    from .replay import serve, write_replay

    if args.console:
        if not args.foxglove or args.run:
            print("error: --console goes with --foxglove and no run folder", file=sys.stderr)
            return 2
        from .foxglove_ws import serve_console_foxglove

        port = _port(args.port, 8765)
        return _serving(serve_console_foxglove, port, args.console, port=port, allow_origins=args.allow_origin)
    if not args.run:
        print("error: a run folder is needed (or --console URL --foxglove)", file=sys.stderr)
        return 2
    if args.foxglove:
        from .foxglove_ws import serve_foxglove

        if not args.speed > 0:
            print("error: --speed must be > 0", file=sys.stderr)
            return 2
        port = _port(args.port, 8765)
        loop = not args.once
        return _serving(
            serve_foxglove, port, args.run, port=port, speed=args.speed, loop=loop, allow_origins=args.allow_origin
        )
    warn_gaps(args.run)
    if args.serve:
        port = _port(args.port, 8060)
        return _serving(serve, port, args.run, port=port, open_browser=args.open, out=args.out)
    path = write_replay(args.run, args.out)
    print(f"wrote {path} (open it in a web browser)")
    if args.open:
        import webbrowser

        webbrowser.open(path.resolve().as_uri())
    return 0
