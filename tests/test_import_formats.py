"""Round trips: a simulated USV run (the truth) written as DataFlash .bin, PX4 .ulg, ROS 2 bag, CSV and
(by the MAVLink vehicle's own telemetry logger) .tlog, imported with ``oceangnc import`` and compared
with the truth; and the bad-input errors (one line naming the file and what is missing, exit 2)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from log_writers import as_pre_iron_bag, write_dataflash, write_rosbag, write_tlog, write_ulog
from oceangnc.cli import main
from oceangnc.io.importers import import_log, read_any
from oceangnc.io.geo import ned_to_latlon

LAT0, LON0 = 63.4305, 10.3951
KGF = 9.80665


@pytest.fixture(scope="module")
def truth(tmp_path_factory):
    import oceangnc

    out = tmp_path_factory.mktemp("truth")
    res = oceangnc.run(
        "usv-remote",
        duration=60.0,
        out=out,
        plots=False,
        overrides={"guidance.waypoints": [(20.0, 0.0), (20.0, 20.0), (0.0, 20.0)], "gps.sigma": 0.0},
    )
    df = res.df
    c = res.config.usv
    return df, c.max_thrust_kgf * KGF, c.max_reverse_kgf * KGF


def _compare(res, df, t_shift, pos_tol=0.05, ang_tol=0.01, act=True):
    """Imported signals against the truth interpolated at the same instants (truth t = t + t0 - shift)."""
    imp = res.df
    t_truth = imp["t"].to_numpy() + res.report["t0_source_s"] - t_shift
    ok = (t_truth >= df["t"].iloc[0]) & (t_truth <= df["t"].iloc[-1])
    assert ok.sum() > 0.9 * len(imp)
    tt = df["t"].to_numpy()

    def at_truth(c):
        return np.interp(t_truth[ok], tt, df[c].to_numpy())

    err = {}
    err["x"] = np.max(np.abs(imp["usv.x"].to_numpy()[ok] - at_truth("usv.x")))
    err["y"] = np.max(np.abs(imp["usv.y"].to_numpy()[ok] - at_truth("usv.y")))
    dpsi = imp["usv.psi"].to_numpy()[ok] - np.interp(t_truth[ok], tt, np.unwrap(df["usv.psi"].to_numpy()))
    err["psi"] = np.max(np.abs((dpsi + np.pi) % (2 * np.pi) - np.pi))
    err["r"] = np.max(np.abs(imp["usv.r"].to_numpy()[ok] - at_truth("usv.r")))
    err["speed"] = np.max(np.abs(imp["usv.speed"].to_numpy()[ok] - at_truth("usv.speed")))
    err["u"] = np.max(np.abs(imp["usv.u"].to_numpy()[ok] - at_truth("usv.u")))
    assert err["x"] < pos_tol and err["y"] < pos_tol, err
    assert err["psi"] < ang_tol and err["r"] < ang_tol, err
    assert err["speed"] < 0.02 and err["u"] < 0.02, err
    if act:
        assert imp["act.left"].abs().max() > 0.05  # the boat was driven
    assert (imp["usv.x"].max() - imp["usv.x"].min()) > 15  # and went somewhere
    return err


def test_dataflash_bin_round_trip(truth, tmp_path):
    df, tmax, trev = truth
    p = tmp_path / "00000001.BIN"
    write_dataflash(p, df, LAT0, LON0, tmax, trev)
    res = import_log(p, rate=10.0, origin=(LAT0, LON0))
    assert res.format == "dataflash"
    _compare(res, df, t_shift=1.0)
    # thrust commands: PWM 1500 +- 400 us back to -1..1 (quantised at 1/400)
    t_truth = res.df["t"].to_numpy() + res.report["t0_source_s"] - 1.0
    idx = np.clip(np.searchsorted(df["t"].to_numpy(), t_truth + 1e-9, side="right") - 1, 0, len(df) - 1)
    tp = df["usv.thrust_port"].to_numpy()[idx]
    want = np.where(tp >= 0, tp / tmax, tp / trev)
    assert np.max(np.abs(res.df["act.left"].to_numpy() - want)) < 0.003


def test_ulog_round_trip(truth, tmp_path):
    df, tmax, trev = truth
    p = tmp_path / "log.ulg"
    write_ulog(p, df, tmax, trev)
    res = import_log(p, rate=10.0)
    assert res.format == "ulog"
    _compare(res, df, t_shift=0.5)


def test_rosbag_round_trip_and_unknown_topic(truth, tmp_path):
    df, tmax, trev = truth
    p = tmp_path / "bag"
    write_rosbag(p, df, tmax, trev, odom_topic="/boat/odom")
    res = import_log(p, rate=10.0, topics={"odometry": "/boat/odom"})
    assert res.format == "rosbag2"
    _compare(res, df, t_shift=100.0)
    with pytest.raises(Exception) as e:
        import_log(p, topics={"odometry": "/nope"})
    assert "no topic /nope (odometry)" in str(e.value) and str(p) in str(e.value)


@pytest.mark.parametrize("distro", ["humble", "foxy"])
def test_pre_iron_sqlite3_bag_without_definitions(truth, tmp_path, distro, capsys):
    """A bag as Foxy / Humble's rosbag2 writes it (sqlite3, no message definitions): rosbags alone refuses
    it; the import reads it with the distro's typestore, says which, and matches the truth."""
    from rosbags.highlevel import AnyReader

    df, tmax, trev = truth
    p = tmp_path / "bag"
    write_rosbag(p, df, tmax, trev)
    as_pre_iron_bag(p, distro)
    with pytest.raises(Exception, match="no type definitions"):  # the failure the issue reports
        with AnyReader([p]):
            pass
    res = import_log(p, rate=10.0)
    assert res.report["ros_distro"] == distro and f"ros2_{distro} typestore" in res.report["typestore"]
    assert ("schema table" if distro == "humble" else "metadata.yaml version 4") in res.report["typestore"]
    _compare(res, df, t_shift=100.0)
    # --ros-distro overrides, the CLI prints which typestore it used; a bad name is one line, exit 2
    assert main(["import", str(p), "--out", str(tmp_path / "o"), "--ros-distro", "galactic"]) == 0
    assert "ros2_galactic typestore" in capsys.readouterr().out
    err = _cli_error(capsys, ["import", str(p), "--out", str(tmp_path / "o2"), "--ros-distro", "hydro"])
    assert "--ros-distro hydro" in err and "humble" in err


def test_mcap_bag_folder_and_bare_storage_files(truth, tmp_path):
    """An MCAP bag written by rosbags' Writer (folder with metadata.yaml), the bare .mcap file alone, and a
    bare Humble-style .db3 file: all import and match the truth."""
    import shutil

    df, tmax, trev = truth
    m = tmp_path / "mc"
    write_rosbag(m, df, tmax, trev, storage="mcap")
    (mc,) = m.glob("*.mcap")
    res = import_log(m, rate=10.0)
    assert res.format == "rosbag2" and res.report["typestore"] == "the bag's own message definitions"
    _compare(res, df, t_shift=100.0)
    bare = tmp_path / "alone" / "flight.mcap"
    bare.parent.mkdir()
    shutil.copy(mc, bare)
    _compare(import_log(bare, rate=10.0), df, t_shift=100.0)
    h = tmp_path / "h"
    write_rosbag(h, df, tmax, trev)
    as_pre_iron_bag(h, "humble")
    (db,) = h.glob("*.db3")
    bare_db = tmp_path / "alone" / "flight.db3"
    shutil.copy(db, bare_db)
    res = import_log(bare_db, rate=10.0)
    assert "ros2_humble" in res.report["typestore"]
    _compare(res, df, t_shift=100.0)


def test_rosbag_navsatfix_and_imu_without_odometry(truth, tmp_path):
    """Position from sensor_msgs/NavSatFix, heading and yaw rate from sensor_msgs/Imu (no odometry)."""
    df, tmax, trev = truth
    p = tmp_path / "bagfix"
    write_rosbag(p, df, tmax, trev, fix_origin=(LAT0, LON0))
    res = import_log(p, rate=10.0, origin=(LAT0, LON0))
    assert res.report["origin_deg"] == [LAT0, LON0]
    imp = res.df
    t_truth = imp["t"].to_numpy() + res.report["t0_source_s"] - 100.0
    for col in ("usv.x", "usv.y"):
        assert np.max(np.abs(imp[col] - np.interp(t_truth, df["t"], df[col]))) < 0.05
    assert np.max(np.abs(imp["usv.r"] - np.interp(t_truth, df["t"], df["usv.r"]))) < 0.01
    assert any("differentiated from the position" in n for n in res.report["notes"])


def test_backward_time_jump_is_dropped_and_reported():
    from oceangnc.io.importers import resample

    t = np.array([0.0, 0.1, 0.2, 0.3, 0.15, 0.25, 0.4, 0.5, 0.6])  # a clock that steps back at 0.3 s
    cols, rep = resample({"usv.x": (t, 10 * t)}, rate=10.0)
    assert rep["time_jumps"] == 1 and rep["jumps"][0]["kind"] == "backwards"
    assert rep["jumps"][0]["samples_dropped"] == 2 and rep["dropped_samples"]["usv.x"] == 2
    assert np.allclose(cols["usv.x"], 10 * cols["t"])  # the kept samples are the monotone ones


def test_csv_with_column_map_round_trip(truth, tmp_path):
    df, _tmax, _trev = truth
    lat, lon = zip(*(ned_to_latlon(n, e, LAT0, LON0) for n, e in zip(df["usv.x"], df["usv.y"])))
    psi = df["usv.psi"].to_numpy()
    csv = pd.DataFrame(
        {
            "time_ms": (df["t"] * 1000).round().astype(int),
            "lat": lat,
            "lon": lon,
            "heading_deg": np.degrees(psi) % 360,
            "rot_dps": np.degrees(df["usv.r"]),
            "vn_kn": (df["usv.u"] * np.cos(psi) - df["usv.v"] * np.sin(psi)) / (1852 / 3600),
            "ve_kn": (df["usv.u"] * np.sin(psi) + df["usv.v"] * np.cos(psi)) / (1852 / 3600),
        }
    )
    p = tmp_path / "trial.csv"
    csv.to_csv(p, index=False)
    res = import_log(
        p,
        rate=10.0,
        origin=(LAT0, LON0),
        column_map=[
            "t=time_ms:ms,lat=lat,lon=lon,usv.psi=heading_deg:deg",
            "usv.r=rot_dps:deg/s,usv.vn=vn_kn:kn,usv.ve=ve_kn:kn",
        ],
    )
    _compare(res, df, t_shift=0.0, act=False)


def test_tlog_from_the_vehicles_own_stream(tmp_path):
    """The MAVLink vehicle logs its telemetry stream (.tlog) while flying a route; the import matches its
    own Parquet log. A fake clock steps the vehicle (no sockets needed, no waiting)."""
    from oceangnc.mavlink.protocol import AUTO
    from oceangnc.mavlink.vehicle import MavlinkVehicle

    now = [0.0]
    v = MavlinkVehicle(
        "usv-remote",
        listen="udp:127.0.0.1:0",
        out_root=tmp_path,
        clock=lambda: now[0],
        tlog=tmp_path / "flight.tlog",
        overrides={"gps.sigma": 0.0},
        mav={"origin_lat_deg": LAT0, "origin_lon_deg": LON0},
    )
    v._arm(True)
    v._set_mode(AUTO, "test")
    while v.sim.t < 40.0:
        now[0] += 0.01
        v.step_once()
    v.close()
    truth = pd.read_parquet(v.run_dir / "log.parquet")
    res = import_log(tmp_path / "flight.tlog", rate=10.0, origin=(LAT0, LON0))
    assert res.format == "tlog" and res.report["system"] == 1
    err = _compare(res, truth, t_shift=0.0, pos_tol=0.02)  # GLOBAL_POSITION_INT is in 1e-7 deg (1 cm)
    assert err["x"] < 0.02
    # the CLI: run folder with log.parquet and import.json
    assert main(["import", str(tmp_path / "flight.tlog"), "--out", str(tmp_path / "imp"), "--rate", "5"]) == 0
    out = pd.read_parquet(tmp_path / "imp" / "log.parquet")
    assert abs(np.median(np.diff(out["t"])) - 0.2) < 1e-9 and "usv.psi" in out


def test_gaps_are_reported_not_interpolated(truth, tmp_path):
    df, tmax, trev = truth
    cut = df[(df["t"] < 20.0) | (df["t"] > 25.0)]  # a 5 s hole in every signal
    p = tmp_path / "hole.ulg"
    write_ulog(p, cut, tmax, trev)
    res = import_log(p, rate=10.0)
    gaps = [g for g in res.report["gaps"] if g["signal"] == "usv.x"]
    assert len(gaps) == 1 and 19.4 < gaps[0]["from_s"] + res.report["t0_source_s"] - 0.5 < 20.2
    hole = (res.df["t"] + res.report["t0_source_s"] - 0.5).between(20.2, 24.8)
    assert res.df.loc[hole, "usv.x"].isna().all() and res.df.loc[~hole, "usv.x"].notna().mean() > 0.97


def test_read_any_passes_parquet_through(truth, tmp_path):
    df, _, _ = truth
    p = tmp_path / "log.parquet"
    df.to_parquet(p)
    assert list(read_any(p).columns) == list(df.columns)


# -- bad input: one line naming the file and what is missing, exit 2 ----------------------------------------


def _cli_error(capsys, argv):
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1, err
    return err


def test_truncated_and_corrupt_logs_exit_2(truth, tmp_path, capsys):
    df, tmax, trev = truth
    p = tmp_path / "full.bin"
    write_dataflash(p, df.iloc[:200], LAT0, LON0, tmax, trev)
    data = p.read_bytes()
    tr = tmp_path / "truncated.bin"
    tr.write_bytes(data[:-7])
    err = _cli_error(capsys, ["import", str(tr), "--out", str(tmp_path / "o1")])
    assert str(tr) in err and "truncated" in err
    assert main(["import", str(tr), "--out", str(tmp_path / "o1b"), "--allow-truncated"]) == 0
    bad = tmp_path / "corrupt.bin"
    bad.write_bytes(data[:500] + b"\x00" * 50 + data[550:])
    err = _cli_error(capsys, ["import", str(bad), "--out", str(tmp_path / "o2")])
    assert str(bad) in err and "corrupt" in err
    junk = tmp_path / "junk.tlog"
    junk.write_bytes(bytes(range(256)) * 40)
    err = _cli_error(capsys, ["import", str(junk), "--out", str(tmp_path / "o3")])
    assert str(junk) in err and "corrupt" in err
    ul = tmp_path / "cut.ulg"
    write_ulog(ul, df.iloc[:100], tmax, trev)
    ul.write_bytes(ul.read_bytes()[:-5])
    err = _cli_error(capsys, ["import", str(ul), "--out", str(tmp_path / "o4")])
    assert str(ul) in err and ("truncated" in err or "corrupt" in err)


def test_csv_missing_column_and_unknown_topic_exit_2(truth, tmp_path, capsys):
    p = tmp_path / "x.csv"
    pd.DataFrame({"time": [0.0, 0.1, 0.2], "hdg": [0, 1, 2]}).to_csv(p, index=False)
    err = _cli_error(capsys, ["import", str(p), "--out", str(tmp_path / "o"), "--map", "t=time,usv.psi=heading:deg"])
    assert str(p) in err and "heading (for usv.psi)" in err
    df, tmax, trev = truth
    b = tmp_path / "bag"
    write_rosbag(b, df.iloc[:50], tmax, trev)
    err = _cli_error(capsys, ["import", str(b), "--out", str(tmp_path / "o5"), "--topic", "odometry=/missing"])
    assert str(b) in err and "/missing" in err


# -- vehicle type and thruster mapping (issue 28) ----------------------------------------------------------


def _want_thrust(df, res, shift, col, tmax, trev):
    t_truth = res.df["t"].to_numpy() + res.report["t0_source_s"] - shift
    idx = np.clip(np.searchsorted(df["t"].to_numpy(), t_truth + 1e-9, side="right") - 1, 0, len(df) - 1)
    tp = df[col].to_numpy()[idx]
    return np.where(tp >= 0, tp / tmax, tp / trev)


def test_servo_functions_map_the_thrusters_and_the_firmware_names_the_boat(truth, tmp_path):
    """ArduRover boat (FRAME_CLASS 2) whose thrusters are on outputs 2 and 4 (SERVO2_FUNCTION 73 ThrottleLeft,
    SERVO4_FUNCTION 74 ThrottleRight, output 4 reversed): read from the PARM records, not outputs 1 and 3."""
    df, tmax, trev = truth
    p = tmp_path / "boat.bin"
    params = {"FRAME_CLASS": 2, "SERVO2_FUNCTION": 73, "SERVO4_FUNCTION": 74, "SERVO4_REVERSED": 1}
    write_dataflash(p, df, LAT0, LON0, tmax, trev, "ArduRover V4.5.7 (e1b2c3d4)", params, outputs=(2, 4), reverse=(4,))
    res = import_log(p, rate=10.0, origin=(LAT0, LON0))
    v = res.report["vehicle"]
    assert v["type"] == "boat" and v["marine"] and "ArduRover V4.5.7" in v["from"] and "FRAME_CLASS=2" in v["from"]
    assert res.report["servo_map"] == {"act.left": 2, "act.right": 4}
    assert any("SERVO2_FUNCTION=73 (ThrottleLeft) -> act.left" in n for n in res.report["notes"])
    assert np.max(np.abs(res.df["act.left"] - _want_thrust(df, res, 1.0, "usv.thrust_port", tmax, trev))) < 0.003
    assert np.max(np.abs(res.df["act.right"] - _want_thrust(df, res, 1.0, "usv.thrust_stbd", tmax, trev))) < 0.003
    # --servos overrides the parameters, and says the log disagrees
    res2 = import_log(p, rate=10.0, servos="skid")
    assert res2.report["servo_map"] == {"act.left": 1, "act.right": 3}
    assert any("--servos wins" in n for n in res2.report["notes"])
    # a ground rover (FRAME_CLASS 1) is no boat
    g = tmp_path / "rover.bin"
    write_dataflash(g, df.iloc[:100], LAT0, LON0, tmax, trev, "ArduRover V4.5.7 (e1b2c3d4)", {"FRAME_CLASS": 1})
    assert import_log(g).report["vehicle"] == {
        "type": "ground rover",
        "from": "MSG 'ArduRover V4.5.7 (e1b2c3d4)', FRAME_CLASS=1",
        "marine": False,
    }


def test_multirotor_logs_are_named_and_their_motors_are_not_thrusters(truth, tmp_path, capsys):
    """A quadcopter's .bin (MSG ArduCopter, SERVO1-4_FUNCTION 33-36 motors), .tlog (HEARTBEAT
    MAV_TYPE_QUADROTOR, no parameters) and .ulg (parameter MAV_TYPE 2): the vehicle is read from the log, the
    motors do not become left / right thrusters, and boat identification refuses each in one line."""
    df, tmax, trev = truth
    part = df.iloc[:300]
    b = tmp_path / "quad.bin"
    motors = {f"SERVO{n}_FUNCTION": 32 + n for n in range(1, 5)}
    write_dataflash(b, part, LAT0, LON0, tmax, trev, "ArduCopter V4.5.7 (2a3dc4b7)", {"FRAME_CLASS": 1, **motors})
    tl = tmp_path / "quad.tlog"
    write_tlog(tl, part, LAT0, LON0, mav_type=2, tmax_n=tmax, trev_n=trev)
    ul = tmp_path / "quad.ulg"
    write_ulog(ul, part, tmax, trev, params={"MAV_TYPE": 2, "SYS_AUTOSTART": 4001})
    for p, src in (
        (b, "MSG 'ArduCopter V4.5.7"),
        (tl, "HEARTBEAT type 2 (MAV_TYPE_QUADROTOR)"),
        (ul, "parameter MAV_TYPE=2"),
    ):
        res = import_log(p, rate=10.0)
        v = res.report["vehicle"]
        assert v["type"] == "multirotor" and v["marine"] is False and v["from"].startswith(src), v
        assert not any(c.startswith("act.") for c in res.df.columns), res.df.columns
        assert any(n.startswith("no actuators imported") for n in res.report["notes"])
        err = _cli_error(capsys, ["identify", "first-order", str(p), "--out", str(tmp_path / "o")])
        assert str(p) in err and "the log is of a multirotor" in err and "--force-vehicle" in err
    # the import itself works and says so; identifying its run folder is refused the same way
    assert main(["import", str(b), "--out", str(tmp_path / "imp")]) == 0
    out = capsys.readouterr().out
    assert "vehicle: multirotor (MSG 'ArduCopter V4.5.7 (2a3dc4b7)', FRAME_CLASS=1): not a boat" in out
    err = _cli_error(capsys, ["identify", "first-order", str(tmp_path / "imp"), "--out", str(tmp_path / "o")])
    assert f"imported from {b}, a multirotor" in err


def test_tlog_boat_with_servo_parameters(truth, tmp_path):
    """A boat's tlog (HEARTBEAT MAV_TYPE_SURFACE_BOAT) with the parameters a ground station downloaded
    (PARAM_VALUE SERVO1_FUNCTION 73, SERVO3_FUNCTION 74): boat, thrusters on 1 and 3 from the parameters."""
    df, tmax, trev = truth
    p = tmp_path / "boat.tlog"
    write_tlog(
        p, df, LAT0, LON0, mav_type=11, params={"SERVO1_FUNCTION": 73, "SERVO3_FUNCTION": 74}, tmax_n=tmax, trev_n=trev
    )
    res = import_log(p, rate=10.0, origin=(LAT0, LON0))
    assert res.report["vehicle"]["type"] == "boat" and res.report["servo_map"] == {"act.left": 1, "act.right": 3}
    assert any("from the log's parameters" in n for n in res.report["notes"])
    _compare(res, df, t_shift=1.0, pos_tol=0.02)
    # GPS_RAW_INT without a 3D fix for the first 4 s: the estimate's positions of that time are dropped
    q = tmp_path / "nofix.tlog"
    write_tlog(q, df, LAT0, LON0, mav_type=11, tmax_n=tmax, trev_n=trev, no_fix_s=4.0)
    res = import_log(q, rate=10.0, origin=(LAT0, LON0))
    assert any("positions while GPS_RAW_INT had no 3D fix (fix_type < 3) dropped" in n for n in res.report["notes"])
    assert res.df["t"].iloc[0] + res.report["t0_source_s"] - 1.0 >= 4.0 - 1e-6
    _compare(res, df, t_shift=1.0, pos_tol=0.02)


# -- trims and plausibility (issue 28) ----------------------------------------------------------------------


def test_start_end_trim_keeps_the_time_axis(truth, tmp_path, capsys):
    df, tmax, trev = truth
    p = tmp_path / "log.ulg"
    write_ulog(p, df, tmax, trev)
    full = import_log(p, rate=10.0)
    part = import_log(p, rate=10.0, start=10.0, end=40.0)
    t = part.df["t"].to_numpy()
    assert (
        abs(t[0] - 10.0) < 0.11 and abs(t[-1] - 40.0) < 0.11 and part.report["trim"] == {"start_s": 10.0, "end_s": 40.0}
    )
    same = full.df.set_index(full.df["t"].round(6)).loc[np.round(t, 6)]  # the same instants, the same values
    for c in ("usv.x", "usv.psi", "act.left"):
        assert np.allclose(same[c].to_numpy(), part.df[c].to_numpy(), atol=1e-9), c
    assert part.report["t0_source_s"] == full.report["t0_source_s"]
    assert main(["import", str(p), "--out", str(tmp_path / "o"), "--start", "5", "--end", "15"]) == 0
    out = pd.read_parquet(tmp_path / "o" / "log.parquet")
    assert out["t"].min() >= 5.0 - 1e-9 and out["t"].max() <= 15.0 + 1e-9
    err = _cli_error(capsys, ["import", str(p), "--out", str(tmp_path / "o2"), "--start", "500"])
    assert str(p) in err and "nothing after --start 500 s (the log runs from 0 to 60.0 s" in err
    err = _cli_error(capsys, ["import", str(p), "--out", str(tmp_path / "o3"), "--start", "20", "--end", "10"])
    assert "the start must come before the end" in err


def test_implausible_heights_are_refused_naming_file_and_column(truth, tmp_path, capsys):
    """A height that leaps to -584 m in one sample (the issue's log), and one below the deepest ocean: one line,
    exit 2, the file and the column named; --end before the leap imports the rest."""
    df, tmax, trev = truth
    part = df.iloc[:400]
    import log_writers

    def ulog_with_z(path, z_of_i):
        w = log_writers.ULogWriter(path)
        w.topic(
            "vehicle_local_position", [("float", "x"), ("float", "y"), ("float", "z"), ("float", "vx"), ("float", "vy")]
        )
        w.topic("vehicle_attitude", [("float[4]", "q")])
        for i in range(len(part)):
            us = round(part["t"].iat[i] * 1e6) + 500_000
            w.write("vehicle_local_position", us, part["usv.x"].iat[i], part["usv.y"].iat[i], z_of_i(i), 1.0, 0.0)
            w.write("vehicle_attitude", us, 1.0, 0.0, 0.0, 0.0)
        w.close()

    leap = tmp_path / "leap.ulg"
    ulog_with_z(leap, lambda i: 584.0 if i >= 300 else 0.1 * math.sin(i / 10))  # z down: height -584 m
    err = _cli_error(capsys, ["import", str(leap), "--out", str(tmp_path / "o")])
    assert str(leap) in err and "column usv.z" in err and "-584.0 m" in err and "implausible" in err
    assert "at t = 14.95 s" in err
    assert main(["import", str(leap), "--out", str(tmp_path / "o2"), "--end", "14"]) == 0
    deep = tmp_path / "deep.ulg"
    ulog_with_z(deep, lambda i: 12_000.0 + i * 0.01)
    err = _cli_error(capsys, ["import", str(deep), "--out", str(tmp_path / "o3")])
    assert str(deep) in err and "column usv.z: height -12000.0 m" in err and "-11000 to 10000 m" in err
    # a slow, steady descent is plausible (a UUV diving at 1 m/s)
    dive = tmp_path / "dive.ulg"
    ulog_with_z(dive, lambda i: 0.05 * i)
    assert import_log(dive).df["usv.z"].max() > 15


# -- sensor instances and GPS fix (issue 28) ----------------------------------------------------------------


def test_two_imus_and_two_gps_pick_one_instance_and_drop_no_fix(truth, tmp_path, capsys):
    """A board with two IMUs and two GPS (ArduPilot 4's instance field I, both instances at the same TimeUS)
    and no GPS fix for the first 5 s: no false time jump, no sample lost, instance 0 (the primary) used and
    reported, the no-fix samples dropped and counted; --instance picks the other."""
    df, tmax, trev = truth
    p = tmp_path / "two.bin"
    write_dataflash(p, df, LAT0, LON0, tmax, trev, instances=2, no_fix_s=5.0)
    res = import_log(p, rate=10.0, origin=(LAT0, LON0))
    rep = res.report
    assert rep["time_jumps"] == 0 and rep["dropped_samples"] == {}, rep["jumps"]
    assert rep["instances"] == {"imu": {"used": 0, "present": [0, 1]}, "gps": {"used": 0, "present": [0, 1]}}
    assert rep["signals"]["usv.r"]["samples"] == len(df)  # every sample of the one instance
    assert rep["gps_no_fix_dropped"] == 50  # 5 s of 5 Hz GPS without a 3D fix
    assert any("IMU: instance 0 of 0, 1" in n for n in rep["notes"])
    assert any("without a 3D fix (Status < 3) dropped" in n for n in rep["notes"])
    assert res.df["t"].iloc[0] + rep["t0_source_s"] - 1.0 >= 5.0 - 0.21  # the log starts at the first 3D fix
    _compare(res, df, t_shift=1.0)
    other = import_log(p, rate=10.0, origin=(LAT0, LON0), instances={"imu": 1, "gps": 1})
    assert other.report["instances"]["imu"]["used"] == 1
    assert np.median(other.df["usv.r"] - res.df["usv.r"]) == pytest.approx(0.05, abs=1e-6)
    assert np.median(other.df["usv.x"] - res.df["usv.x"]) == pytest.approx(3.0, abs=0.02)
    err = _cli_error(capsys, ["import", str(p), "--out", str(tmp_path / "o0"), "--instance", "imu"])
    assert "--instance 'imu': expected SENSOR=N" in err
    err = _cli_error(capsys, ["import", str(p), "--out", str(tmp_path / "o"), "--instance", "imu=2"])
    assert str(p) in err and "no such IMU instance; the log has 0, 1" in err
    assert main(["import", str(p), "--out", str(tmp_path / "o2"), "--instance", "gps=1"]) == 0
    assert "note: GPS: instance 1 of 0, 1 (--instance" in capsys.readouterr().out


def test_navsatfix_without_a_fix_is_dropped(truth, tmp_path):
    """sensor_msgs/NavSatFix with status -1 (no fix) are dropped and counted."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    df, _, _ = truth
    ts = get_typestore(Stores.ROS2_HUMBLE)
    Fix, St = ts.types["sensor_msgs/msg/NavSatFix"], ts.types["sensor_msgs/msg/NavSatStatus"]
    Hdr, Time = ts.types["std_msgs/msg/Header"], ts.types["builtin_interfaces/msg/Time"]
    p = tmp_path / "fix"
    with Writer(p, version=8) as w:
        c = w.add_connection("/fix", Fix.__msgtype__, typestore=ts)
        for i in range(0, 400):
            t = 100.0 + float(df["t"].iat[i])
            lat, lon = ned_to_latlon(float(df["usv.x"].iat[i]), float(df["usv.y"].iat[i]), LAT0, LON0)
            no_fix = i < 40
            m = Fix(
                header=Hdr(stamp=Time(sec=int(t), nanosec=round((t - int(t)) * 1e9)), frame_id="gps"),
                status=St(status=-1 if no_fix else 0, service=1),
                latitude=0.0 if no_fix else lat,
                longitude=0.0 if no_fix else lon,
                altitude=0.0,
                position_covariance=np.zeros(9),
                position_covariance_type=0,
            )
            w.write(c, round(t * 1e9), ts.serialize_cdr(m, Fix.__msgtype__))
    res = import_log(p, rate=10.0, origin=(LAT0, LON0))
    assert any("40 of 400 NavSatFix messages without a fix (status -1) dropped" in n for n in res.report["notes"])
    t_truth = res.df["t"].to_numpy() + res.report["t0_source_s"] - 100.0
    assert t_truth[0] == pytest.approx(df["t"].iat[40], abs=1e-6)
    assert np.max(np.abs(res.df["usv.x"] - np.interp(t_truth, df["t"], df["usv.x"]))) < 0.05


def test_px4_vehicle_status_and_gps_fix(truth, tmp_path, capsys):
    """PX4 without a MAV_TYPE parameter: vehicle_status.vehicle_type (2 fixed wing) names the vehicle (and
    boat identification refuses it), SYS_AUTOSTART 60001 a submarine; vehicle_gps_position samples with
    fix_type < 3 are dropped and counted."""
    import log_writers

    df, _, _ = truth
    part = df.iloc[:400]

    def ulog(path, vehicle_type=None, params=None):
        w = log_writers.ULogWriter(path)
        for k, v in (params or {}).items():
            w.param(k, v)
        w.topic("vehicle_gps_position", [("int32_t", "lat"), ("int32_t", "lon"), ("uint8_t", "fix_type")])
        w.topic("vehicle_attitude", [("float[4]", "q")])
        if vehicle_type is not None:
            w.topic("vehicle_status", [("uint8_t", "vehicle_type"), ("bool", "is_vtol")])
        for i in range(len(part)):
            us = round(part["t"].iat[i] * 1e6) + 500_000
            fix = i >= 40
            lat, lon = ned_to_latlon(part["usv.x"].iat[i] + (0 if fix else 800.0), part["usv.y"].iat[i], LAT0, LON0)
            w.write("vehicle_gps_position", us, round(lat * 1e7), round(lon * 1e7), 3 if fix else 1)
            psi = part["usv.psi"].iat[i]
            w.write("vehicle_attitude", us, math.cos(psi / 2), 0.0, 0.0, math.sin(psi / 2))
            if vehicle_type is not None and i % 20 == 0:
                w.write("vehicle_status", us, vehicle_type, False)
        w.close()

    plane = tmp_path / "plane.ulg"
    ulog(plane, vehicle_type=2)
    res = import_log(plane, rate=10.0, origin=(LAT0, LON0))
    assert res.report["vehicle"] == {"type": "fixed-wing", "from": "vehicle_status.vehicle_type=2", "marine": False}
    assert any("40 of 400 samples without a 3D fix (fix_type < 3) dropped" in n for n in res.report["notes"])
    t_truth = res.df["t"].to_numpy() + res.report["t0_source_s"] - 0.5
    assert t_truth[0] == pytest.approx(part["t"].iat[40], abs=1e-6)
    assert np.max(np.abs(res.df["usv.x"] - np.interp(t_truth, part["t"], part["usv.x"]))) < 0.05
    err = _cli_error(capsys, ["identify", "first-order", str(plane), "--out", str(tmp_path / "o")])
    assert "the log is of a fixed-wing (vehicle_status.vehicle_type=2)" in err
    sub = tmp_path / "sub.ulg"
    ulog(sub, params={"SYS_AUTOSTART": 60001})
    assert import_log(sub).report["vehicle"] == {"type": "submarine", "from": "SYS_AUTOSTART=60001", "marine": True}


@pytest.mark.parametrize(
    "firmware, kind",
    [
        ("APM:Copter V3.4.6 (e707341b)", "multirotor"),
        ("APM:Copter V3.3.3-rc2 (e5ab6d36)", "multirotor"),
        ("APM:Plane V3.4.0 (3f4a2db7)", "fixed-wing"),
    ],
)
def test_pre_3_5_firmware_strings_are_recognised_and_refused_as_not_boats(truth, tmp_path, capsys, firmware, kind):
    """ArduPilot before 3.5 wrote "APM:Copter V3.x" (its THISFIRMWARE): such a log is a drone, refused for
    boat identification with only --force-vehicle offered, and no --skip-check turns it into a boat model."""
    df, tmax, trev = truth
    b = tmp_path / "old.bin"
    motors = {f"SERVO{n}_FUNCTION": 32 + n for n in range(1, 5)}
    write_dataflash(b, df.iloc[:300], LAT0, LON0, tmax, trev, firmware, motors)
    v = import_log(b, rate=10.0).report["vehicle"]
    assert v["type"] == kind and v["marine"] is False, v
    skips = [a for c in ("bound", "condition", "fit", "whiteness") for a in ("--skip-check", c)]
    for extra in ([], skips):
        err = _cli_error(capsys, ["identify", "first-order", str(b), "--out", str(tmp_path / "o"), *extra])
        assert f"the log is of a {kind}" in err and "--force-vehicle" in err and "--skip-check" not in err, err
    assert not (tmp_path / "o").exists()


def test_surface_vehicle_tlog_altitude_is_not_imported_as_depth(truth, tmp_path):
    """A boat's relative altitude (GLOBAL_POSITION_INT.relative_alt, measured from home; ArduRover's leaps
    when home is set) is no depth: not imported, with a note, so the leap cannot refuse the file."""
    df, tmax, trev = truth
    tl = tmp_path / "boat.tlog"
    write_tlog(tl, df.iloc[:300], LAT0, LON0, mav_type=11, tmax_n=tmax, trev_n=trev)
    res = import_log(tl, rate=10.0)
    assert res.report["vehicle"]["type"] == "boat" and "usv.x" in res.df.columns
    assert "usv.z" not in res.df.columns
    assert any("not a depth" in n for n in res.report["notes"])
