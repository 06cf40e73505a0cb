"""``oceangnc import LOG --out RUN_DIR [--rate 10] [--map t=time,...] [--topic odometry=/odom]``."""

from __future__ import annotations


def add_source_options(p) -> None:
    """Options shared by ``oceangnc import`` and the ``identify`` commands for reading field logs."""
    g = p.add_argument_group("field logs (.bin .tlog .ulg ROS 2 bag, CSV with a column map)")
    g.add_argument("--rate", type=float, default=10.0, help="resampling rate of a field log, Hz (default 10)")
    g.add_argument(
        "--format",
        dest="log_format",
        choices=["dataflash", "tlog", "ulog", "rosbag2", "csv"],
        help="log format (default: from the file name)",
    )
    g.add_argument(
        "--map",
        action="append",
        metavar="SIGNAL=COLUMN[:UNIT]",
        help="CSV column map, e.g. t=time:ms,usv.psi=heading:deg,lat=lat,lon=lon (repeatable)",
    )
    g.add_argument(
        "--topic",
        action="append",
        metavar="ROLE=TOPIC",
        help="ROS 2 topic of a role (odometry, imu, navsat, actuators), e.g. odometry=/boat/odom",
    )
    g.add_argument(
        "--ros-distro",
        metavar="DISTRO",
        help="ROS 2 distribution whose message types read a bag without definitions (Foxy, Galactic, Humble "
        "sqlite3); default: the bag's ros_distro, else humble",
    )
    g.add_argument(
        "--servos",
        choices=["skid", "rudder"],
        help="ArduPilot servo outputs 1 and 3 (.bin RCOU, .tlog SERVO_OUTPUT_RAW) as skid = left / right "
        "thrusters or rudder = steering / throttle (default: the log's SERVOn_FUNCTION parameters, "
        "73/74 left/right, 26 steering, 70 throttle; without them skid)",
    )
    g.add_argument(
        "--instance",
        action="append",
        metavar="SENSOR=N",
        help="ArduPilot .bin sensor instance to read, imu=N or gps=N (repeatable; default the first, the "
        "primary, and the import says which)",
    )
    g.add_argument("--body", default="usv", help="prefix of the vehicle's signals (default usv; uuv for a UUV)")
    g.add_argument("--system", type=int, help="MAVLink system id to read from a .tlog (default: the first vehicle)")
    g.add_argument(
        "--origin",
        nargs=2,
        type=float,
        metavar=("LAT", "LON"),
        help="origin of the local NED frame, deg (default: the first fix)",
    )
    g.add_argument(
        "--gap",
        type=float,
        help="longest interval without a sample that is interpolated, s "
        "(default max(1, 5/rate)); longer ones are gaps (NaN rows)",
    )
    g.add_argument("--allow-truncated", action="store_true", help="import the complete records of a truncated log")
    g.add_argument(
        "--start",
        type=float,
        metavar="S",
        help="keep the log from this time, s (the imported time axis: 0 where every signal has started)",
    )
    g.add_argument("--end", type=float, metavar="S", help="keep the log up to this time, s (same axis as --start)")


def source_options(args) -> dict:
    from ...errors import InputError

    topics = {}
    for it in getattr(args, "topic", None) or []:
        if "=" not in it:
            raise InputError(f"--topic {it!r}: expected ROLE=TOPIC, e.g. odometry=/odom")
        k, v = it.split("=", 1)
        topics[k.strip()] = v.strip()
    instances = {}
    for it in getattr(args, "instance", None) or []:
        k, sep, v = it.partition("=")
        if not sep or not v.strip().isdigit():
            raise InputError(f"--instance {it!r}: expected SENSOR=N, e.g. imu=1 or gps=0")
        instances[k.strip().lower()] = int(v)
    opts = {
        "rate": args.rate,
        "fmt": args.log_format,
        "gap_s": args.gap,
        "allow_truncated": args.allow_truncated,
        "servos": args.servos,
        "body": args.body,
    }
    if args.map:
        opts["column_map"] = args.map
    if topics:
        opts["topics"] = topics
    if instances:
        opts["instances"] = instances
    for k in ("start", "end"):
        if getattr(args, k, None) is not None:
            opts[k] = getattr(args, k)
    if getattr(args, "ros_distro", None):
        opts["ros_distro"] = args.ros_distro
    if args.system is not None:
        opts["system"] = args.system
    if args.origin:
        opts["origin"] = tuple(args.origin)
    return opts


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "import",
        help="field log (.bin .tlog .ulg ROS 2 bag CSV) -> run folder with log.parquet (standard signals, SI)",
        description="Convert an ArduPilot DataFlash .bin or telemetry .tlog, a PX4 .ulg, "
        "a ROS 2 bag or a CSV with a column map into the project's Parquet "
        "log; see docs/mavlink-and-logs.md for the signal mapping.",
    )
    p.add_argument("log", help="log file (or ROS 2 bag folder)")
    p.add_argument("--out", required=True, help="run folder to write (log.parquet, import.json)")
    add_source_options(p)
    p.set_defaults(func=_cmd)


def _cmd(args) -> int:
    from .core import import_log, write_run

    opts = source_options(args)
    res = import_log(args.log, **opts)
    path = write_run(res, args.out)
    print(res.summary_line())
    v = res.report.get("vehicle", {})
    not_boat = ": not a boat (identify refuses it unless --force-vehicle)" if v.get("marine") is False else ""
    print(f"  vehicle: {v.get('type', 'unknown')} ({v.get('from', '')}){not_boat}")
    for g in res.report.get("gaps", [])[:10]:
        print(f"  gap in {g['signal']}: {g['from_s']:.2f}-{g['to_s']:.2f} s ({g['rows_left_nan']} rows left NaN)")
    for j in res.report.get("jumps", [])[:10]:
        print(f"  time jump in {j['signal']}: {j['kind']} at {j['at_s']:.3f} s")
    dups = res.report.get("duplicate_stamps", {})
    if dups:
        worst = max(dups, key=dups.get)
        print(f"  note: repeated time stamps (later sample dropped, not a time jump): {worst} {dups[worst]}")
    for n in res.report.get("notes", []):
        print(f"  note: {n}")
    print(f"wrote {path} ({', '.join(c for c in res.df.columns if c != 't')})")
    return 0
