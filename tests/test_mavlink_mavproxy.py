"""The MAVLink vehicle flown by MAVProxy (the ``mavproxy`` package), scripted through its command line on
stdin: load a 3-waypoint mission, arm, AUTO, wait for the last MISSION_ITEM_REACHED, which MAVProxy
forwards to a second UDP output where this test listens. 127.0.0.1 only; every wait is bounded."""

from __future__ import annotations

import os
import shutil
import socket
import sys
import time

import pytest

from mavlink_gcs import MAVProxy, wait_for
from oceangnc.io.geo import ned_to_latlon
from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle

pytest.importorskip("MAVProxy")
MAVPROXY = shutil.which("mavproxy.py") or os.path.join(os.path.dirname(sys.executable), "mavproxy.py")


def _write_wpl(path, pts, lat0, lon0):
    """QGC WPL 110 file: item 0 home, then NAV_WAYPOINT (16) items, frame 3 (global, relative alt)."""
    lines = ["QGC WPL 110"]
    for i, (n, e) in enumerate(pts):
        lat, lon = ned_to_latlon(n, e, lat0, lon0)
        lines.append(f"{i}\t{1 if i == 0 else 0}\t{0 if i == 0 else 3}\t16\t0\t0\t0\t0\t{lat:.8f}\t{lon:.8f}\t0\t1")
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.skipif(not os.path.exists(MAVPROXY), reason="mavproxy.py not installed")
def test_mavproxy_mission_arm_auto_reaches_last_waypoint(tmp_path):
    v = MavlinkVehicle(
        "usv-remote",
        listen="udp:127.0.0.1:0",
        speed=12.0,
        out_root=tmp_path,
        mav={"origin_lat_deg": -35.363261, "origin_lon_deg": 149.165230},
    )
    v.start()
    # the test's own listener: MAVProxy forwards everything the vehicle sends to it
    lsock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    lsock.bind(("127.0.0.1", 0))
    lsock.settimeout(0.05)
    out_port = lsock.getsockname()[1]
    pts = [(0.0, 0.0), (15.0, 0.0), (15.0, 15.0), (0.0, 15.0)]
    _write_wpl(tmp_path / "mission.txt", pts, v.cfg_mav.origin_lat_deg, v.cfg_mav.origin_lon_deg)
    mp = MAVProxy(
        MAVPROXY,
        v.address[1],
        f"--out=udpout:127.0.0.1:{out_port}",
        "--default-modules=wp,arm,mode,cmdlong,param",
        cwd=tmp_path,
    )
    expect, send = mp.expect, mp.send

    parser = M.MAVLink(None)
    parser.robust_parsing = True
    try:
        expect("Detected vehicle 1:1", 60.0)  # MAVProxy starts slowly on a busy machine
        send(f"wp load {tmp_path / 'mission.txt'}")
        expect("MISSION_ACK: TYPE_MISSION: ACCEPTED", 15.0)
        assert len(v.mission) == 4
        send("arm throttle")
        expect("COMPONENT_ARM_DISARM: ACCEPTED", 15.0)
        send("mode AUTO")
        expect("DO_SET_MODE: ACCEPTED", 15.0)
        # wait (bounded) for MISSION_ITEM_REACHED seq 3 as forwarded by MAVProxy on its --out link
        reached = []
        t_end = time.monotonic() + 40.0
        while time.monotonic() < t_end and 3 not in reached:
            try:
                data, _ = lsock.recvfrom(65535)
            except TimeoutError:
                continue
            for m in parser.parse_buffer(data) or []:
                if m.get_type() == "MISSION_ITEM_REACHED":
                    reached.append(m.seq)
        assert reached == [1, 2, 3], reached
        expect("Reached waypoint #3", 10.0)
        assert v.reached == [1, 2, 3]
        assert v.armed and v.counts["rx_bad"] == 0
        # MAVProxy's GUIDED "fly to" (MISSION_ITEM_INT current = 2), a parameter, and Return
        expect("Mission complete", 15.0)
        send("param set CRUISE_SPEED 1.0")
        t_end = time.monotonic() + 15.0
        while time.monotonic() < t_end and v.params["CRUISE_SPEED"].get() != pytest.approx(1.0):
            time.sleep(0.1)
        assert v.params["CRUISE_SPEED"].get() == pytest.approx(1.0)
        send("mode GUIDED")
        expect("Mode GUIDED", 15.0)
        glat, glon = ned_to_latlon(25.0, 5.0, v.cfg_mav.origin_lat_deg, v.cfg_mav.origin_lon_deg)
        send(f"guided {glat:.8f} {glon:.8f} 0")
        expect("Reached destination", 60.0)
        send("mode RTL")
        expect("Reached home", 60.0)
    finally:
        mp.close()
        lsock.close()
        v.stop()
    # the run's log shows the boat within the acceptance radius (3 m) of each waypoint
    import pandas as pd

    df = pd.read_parquet(v.run_dir / "log.parquet")
    for n, e in [*pts[1:], (25.0, 5.0), (0.0, 0.0)]:  # the mission, MAVProxy's guided point, home
        assert (((df["usv.x"] - n) ** 2 + (df["usv.y"] - e) ** 2) ** 0.5).min() < 3.5
    assert df.loc[df["mavlink.mode"] == 15, "usv.u_d"].max() == pytest.approx(1.0, abs=1e-6)  # CRUISE_SPEED


@pytest.mark.skipif(not os.path.exists(MAVPROXY), reason="mavproxy.py not installed")
def test_mavproxy_rc_override_flies_the_rov(tmp_path):
    """MAVProxy's own ``rc 5 1700`` (RC_CHANNELS_OVERRIDE, 18 channels, resent at 10 Hz) on the BlueROV2 of
    rov-station-keeping (an ArduSub vehicle, MANUAL): a forward force by ArduSub's channel map, no heave force
    from the channels MAVProxy leaves at 0, and ``rc clear`` takes it away."""
    v = MavlinkVehicle("rov-station-keeping", listen="udp:127.0.0.1:0", speed=4.0, out_root=tmp_path)
    v.start()
    mp = MAVProxy(MAVPROXY, v.address[1], "--default-modules=rc,arm,cmdlong", cwd=tmp_path)
    expect, send = mp.expect, mp.send

    b = v.sim.bus
    try:
        expect("Detected vehicle 1:1", 60.0)
        send("arm throttle")
        expect("COMPONENT_ARM_DISARM: ACCEPTED", 15.0)
        send("rc 5 1700")
        assert wait_for(lambda: b["vehicle.tau_X"] > 10.0, 15.0, step=0.05), b["vehicle.tau_X"]
        assert b["vehicle.tau_Z"] == 0.0 and b["vehicle.tau_N"] == 0.0 and b["vehicle.tau_Y"] == 0.0
        send("rc clear")
        assert wait_for(lambda: b["vehicle.tau_X"] == 0.0, 15.0, step=0.05), b["vehicle.tau_X"]
        assert v.counts["rx_bad"] == 0
    finally:
        mp.close()
        v.stop()
