"""``oceangnc mavlink [SCENARIO] --listen udp:127.0.0.1:14550 [--gcs udp:HOST:PORT] [--speed 1]
[--foxglove [PORT] [--token-file F]]``."""

from __future__ import annotations

import argparse

from ..cli_options import add_live_options, needs_package, set_overrides


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "mavlink",
        help="serve a live scenario as a MAVLink vehicle (ArduPilot Rover / ArduSub modes) "
        "for QGroundControl, Mission Planner, MAVProxy",
        description="The running scenario appears as a MAVLink 2 vehicle: USV system 1 "
        "(SURFACE_BOAT, Rover's modes), the towed UUV system 2 (SUBMARINE, ArduSub's modes, depth by the "
        "winch), a ROV of a vehicle file system 1 (SUBMARINE, ArduSub's modes). See docs/mavlink-and-logs.md.",
    )
    p.add_argument(
        "scenario",
        nargs="?",
        default="usv-remote",
        help="live scenario (default usv-remote; combined-survey adds the UUV and the cable)",
    )
    p.add_argument(
        "--listen",
        default="udp:127.0.0.1:14550",
        help="UDP address to bind; ground stations sending to it get telemetry back (default udp:127.0.0.1:14550)",
    )
    p.add_argument(
        "--gcs",
        action="append",
        metavar="udp:HOST:PORT",
        help="also send telemetry to this address from the start (a GCS listening, repeatable)",
    )
    add_live_options(
        p,
        "override a config key (repeatable); mavlink.* keys set the endpoint, e.g. "
        "mavlink.origin_lat_deg=59.9 mavlink.gcs_timeout_s=1.5",
        "folder for the run's log (default runs/)",
    )
    p.add_argument("--duration", type=float, help="end after this much simulated time, s (default: until Ctrl-C)")
    p.add_argument(
        "--model",
        help="identified model file (identified.toml from 'oceangnc identify'): the "
        "vehicle's parameters (--set still wins)",
    )
    p.add_argument(
        "--no-tlog",
        action="store_true",
        help="do not write telemetry.tlog (every packet sent, stamped with simulated time) in the run folder",
    )
    p.add_argument(
        "--params",
        metavar="FILE",
        help="start with these parameter values: a run's params.json, or a MAVProxy / Mission Planner "
        ".param file (NAME VALUE per line); see docs/mavlink-and-logs.md",
    )
    p.add_argument(
        "--foxglove",
        nargs="?",
        type=int,
        const=8765,
        metavar="PORT",
        help="also publish the running vehicle as a live Foxglove WebSocket stream on ws://127.0.0.1:PORT "
        "(default 8765; 0: any free port) with a session token, printed in its URL (docs/view.md)",
    )
    p.add_argument(
        "--token-file",
        metavar="PATH",
        help="--foxglove: read the stream's token from the first line of PATH (default: $OCEANGNC_CONSOLE_TOKEN, "
        "else a new random one)",
    )
    p.add_argument(
        "--allow-origin",
        action="append",
        default=[],
        metavar="URL",
        help="--foxglove: a browser origin to accept besides the Foxglove web app and pages of this machine",
    )
    p.add_argument("--quiet", action="store_true", help="do not print the vehicle's events")
    p.set_defaults(func=_cmd)


def _cmd(args) -> int:
    from ..errors import InputError, Terminated

    try:
        from .vehicle import MavlinkVehicle
    except ModuleNotFoundError as e:
        raise InputError(needs_package("oceangnc mavlink", e.name, "field")) from None

    if args.duration is not None and not args.duration > 0:
        raise InputError(f"--duration {args.duration}: must be > 0 s")
    token = None
    if args.foxglove is not None or args.token_file is not None:
        if args.foxglove is None:
            raise InputError("--token-file goes with --foxglove")
        if not (0 <= args.foxglove < 65536):
            raise InputError(f"--foxglove {args.foxglove}: allowed range 0 <= port <= 65535 (0: any free port)")
        from ..console.cli import _check_port, _given_token

        if args.foxglove:
            _check_port("127.0.0.1", args.foxglove)  # a port in use: one line, exit 2, before the vehicle starts

        token, source = _given_token(argparse.Namespace(token_file=args.token_file, token=None))
        if token is not None and (len(token) < 8 or not token.isprintable() or " " in token):
            raise InputError(f"{source}: the token needs at least 8 printable characters without spaces")
    sets = set_overrides(args)
    mav = {k[len("mavlink.") :]: v for k, v in sets.items() if k.startswith("mavlink.")}
    over = {k: v for k, v in sets.items() if not k.startswith("mavlink.")}
    if args.model:
        from ..identification.model_file import load_model_overrides

        over = {**load_model_overrides(args.model), **over}
    v = MavlinkVehicle(
        args.scenario,
        overrides=over,
        mav=mav,
        listen=args.listen,
        gcs=args.gcs,
        speed=args.speed,
        out_root=args.out,
        duration=args.duration,
        verbose=not args.quiet,
        tlog=None if args.no_tlog else "telemetry.tlog",
        params=args.params,
    )
    # SIGTERM ends the vehicle as Ctrl-C does: serve() closes the log (compacted) and writes summary.json;
    # installed before the "Ctrl-C to stop" line, so that a signal right after it finds the handler
    from ..core.interrupts import terminate_like_ctrl_c

    restore = terminate_like_ctrl_c()
    stream = None
    try:
        if args.foxglove is not None:
            from ..view.foxglove_ws import start_vehicle_foxglove

            stream = start_vehicle_foxglove(v, args.foxglove, token, args.allow_origin)
            if stream is None:
                v.close()
                return 2
        if not args.quiet:
            print(
                f"oceangnc mavlink: {v.scenario.name} on udp:{v.address[0]}:{v.address[1]} "
                f"(speed {v.speed:g}x); log {v.run_dir}; Ctrl-C to stop",
                flush=True,
            )
        v.serve()
    except KeyboardInterrupt as e:
        if v.stopped_by is None:  # (a signal before serve() took over)
            v.stopped_by = "SIGTERM" if isinstance(e, Terminated) else "SIGINT"
        v.close()
    finally:
        if restore is not None:
            restore()
        if stream is not None:
            stream.stop()
    if v.run_dir is not None and (not args.quiet or v.stopped_by):
        status = f" (summary.json status: interrupted by {v.stopped_by})" if v.stopped_by else ""
        print(f"log written: {v.run_dir / 'log.parquet'}{status}", flush=True)
    if v.stopped_by:
        return 143 if v.stopped_by == "SIGTERM" else 130
    return 1 if v.error else 0
