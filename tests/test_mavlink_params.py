"""The parameter protocol (issue 28) with plain pymavlink and with MAVSDK's Param plugin: every tunable listed
under ArduPilot Rover's names, read by name and index, PARAM_SET echoed with the value held (a refused value
echoes the unchanged one), the change acting on the running simulation, saved in the run's params.json and
reloaded with --params. 127.0.0.1 only, every wait bounded."""

from __future__ import annotations

import json
import math
import time

import pandas as pd
import pytest

from mavlink_gcs import mavsdk_system, served
from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle

ROVER_NAMES = {"CRUISE_SPEED", "WP_RADIUS", "LOIT_RADIUS", "FS_GCS_TIMEOUT", "FS_GCS_ENABLE", "FS_ACTION",
               "FS_TIMEOUT", "ATC_STR_RAT_P", "ATC_STR_RAT_I", "ATC_STR_RAT_D", "ATC_SPEED_P", "ATC_SPEED_I",
               "ATC_SPEED_D", "ATC_STR_ANG_P", "SYSID_THISMAV", "SYSID_MYGCS"}  # fmt: skip


def _name(m) -> str:
    return m.param_id.rstrip("\x00") if isinstance(m.param_id, str) else m.param_id.decode().rstrip("\x00")


def _set(g, name, value, kind=M.MAV_PARAM_TYPE_REAL32):
    g.mav.param_set_send(1, 1, name.encode(), value, kind)
    return g.wait("PARAM_VALUE", 3.0, lambda m: _name(m) == name)


@pytest.fixture
def vehicle(tmp_path):
    with served(out_root=tmp_path, speed=8.0) as vg:
        yield vg


def test_list_read_set_echo_refuse_and_effect(vehicle, tmp_path):
    v, g = vehicle
    g.wait("HEARTBEAT", 3.0)
    g.mav.param_request_list_send(1, 1)
    got: dict[int, tuple[str, float]] = {}
    first = g.wait("PARAM_VALUE", 3.0)
    got[first.param_index] = (_name(first), first.param_value)
    while len(got) < first.param_count:
        m = g.wait("PARAM_VALUE", 3.0)
        got[m.param_index] = (_name(m), m.param_value)
        assert m.param_count == first.param_count
    names = {n for n, _ in got.values()}
    assert sorted(got) == list(range(first.param_count)) and len(names) == first.param_count
    assert ROVER_NAMES <= names, ROVER_NAMES - names
    values = dict(got.values())
    assert values["FS_GCS_TIMEOUT"] == 5.0 and values["FS_ACTION"] == 2 and values["CRUISE_SPEED"] == pytest.approx(0.7)
    # read by name (index -1) and by index
    g.mav.param_request_read_send(1, 1, b"WP_RADIUS", -1)
    m = g.wait("PARAM_VALUE", 3.0, lambda m: _name(m) == "WP_RADIUS")
    assert m.param_value == pytest.approx(3.0) and got[m.param_index][0] == "WP_RADIUS"
    g.mav.param_request_read_send(1, 1, b"", 2)
    assert _name(g.wait("PARAM_VALUE", 3.0, lambda m: m.param_index == 2)) == got[2][0]
    # set: the echo carries the accepted value, the controller's parameter array holds it
    assert _set(g, "ATC_SPEED_P", 420.0).param_value == 420.0
    pilot = next(b for b in v.sim.blocks if type(b).__name__ == "USVRateController")
    assert pilot.speed_pid.kp == 420.0
    m = _set(g, "FS_ACTION", 1, M.MAV_PARAM_TYPE_INT8)
    assert m.param_value == 1 and m.param_type == M.MAV_PARAM_TYPE_INT8 and v.cfg_mav.fs_action == 1
    # refused (out of range, not finite, not whole, read-only): the echo is the unchanged value
    for name, bad, held in (("CRUISE_SPEED", 50.0, 0.7), ("CRUISE_SPEED", math.nan, 0.7),
                            ("FS_GCS_TIMEOUT", 0.0, 5.0), ("FS_GCS_TIMEOUT", math.inf, 5.0),
                            ("FS_ACTION", 2.5, 1.0), ("FS_ACTION", 7, 1.0), ("SYSID_THISMAV", 9, 1.0)):  # fmt: skip
        assert _set(g, name, bad).param_value == pytest.approx(held), (name, bad)
    assert v.counts["rx_out_of_range"] >= 7 and v.cfg_mav.gcs_timeout_s == 5.0
    # CRUISE_SPEED acts on the running route pilot: fly the default route in AUTO
    assert _set(g, "CRUISE_SPEED", 1.1).param_value == pytest.approx(1.1)
    g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM).result == M.MAV_RESULT_ACCEPTED
    g.mav.set_mode_send(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 10)
    g.wait("HEARTBEAT", 3.0, lambda m: m.custom_mode == 10)
    g.pump(4.0)
    saved = json.loads((v.run_dir / "params.json").read_text())
    assert saved["CRUISE_SPEED"] == pytest.approx(1.1) and saved["ATC_SPEED_P"] == 420.0 and saved["FS_ACTION"] == 1
    v.stop()
    df = pd.read_parquet(v.run_dir / "log.parquet")
    assert df["usv.u_d"].max() == pytest.approx(1.1, abs=1e-6)  # the pilot's setpoint is the new cruise speed
    assert df["usv.u"].max() > 0.8  # and the boat went faster than the old one (0.7 m/s)


def test_params_file_reloads_and_refuses(tmp_path, capsys):
    from oceangnc.cli import main

    f = tmp_path / "boat.param"
    f.write_text("# MAVProxy style\nCRUISE_SPEED 0.9\nFS_GCS_TIMEOUT,3\nATC_STR_RAT_P 250\n")
    args = ["mavlink", "usv-remote", "--listen", "udp:127.0.0.1:0", "--speed", "20", "--duration", "1", "--quiet"]
    assert main([*args, "--out", str(tmp_path / "a"), "--params", str(f)]) == 0
    (run,) = list((tmp_path / "a").glob("mavlink-usv-remote-*"))
    saved = json.loads((run / "params.json").read_text())
    assert saved["CRUISE_SPEED"] == pytest.approx(0.9) and saved["FS_GCS_TIMEOUT"] == 3.0
    assert saved["ATC_STR_RAT_P"] == 250.0
    # the run's params.json is itself a --params file: the next run starts where this one ended
    assert main([*args, "--out", str(tmp_path / "b"), "--params", str(run / "params.json")]) == 0
    (run2,) = list((tmp_path / "b").glob("mavlink-usv-remote-*"))
    assert json.loads((run2 / "params.json").read_text()) == saved
    bad = tmp_path / "bad.param"
    for text, msg in (("CRUISE_SPEED 99\n", "CRUISE_SPEED = 99 refused"), ("NOPE 1\n", "unknown parameter NOPE"),
                      ("CRUISE_SPEED\n", "expected NAME VALUE")):  # fmt: skip
        bad.write_text(text)
        assert main([*args, "--out", str(tmp_path / "c"), "--params", str(bad)]) == 2
        err = capsys.readouterr().err
        assert msg in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "c").exists() or not list((tmp_path / "c").glob("mavlink-*"))


def test_mavsdk_set_and_get_param(tmp_path):
    pytest.importorskip("mavsdk")
    from mavsdk.plugins.param import Param

    v = MavlinkVehicle("combined-survey", listen="udp:127.0.0.1:0", speed=1.0, out_root=tmp_path)
    v.start()
    try:
        sdk, system = mavsdk_system(v)  # noqa: F841 (sdk kept alive)
        par = Param(system)
        assert par.get_param_float("WP_RADIUS") == pytest.approx(2.0)
        par.set_param_float("WP_RADIUS", 4.5)
        assert par.get_param_float("WP_RADIUS") == pytest.approx(4.5)
        pp = next(b for b in v.sim.blocks if type(b).__name__ == "PurePursuit")
        assert pp.acceptance == pytest.approx(4.5)  # the guidance of the running simulation
        par.set_param_float("ATC_HDG_D", 90.0)
        ctl = next(b for b in v.sim.blocks if type(b).__name__ == "USVController")
        assert ctl.heading.kd == 90.0
        par.set_param_int("FS_ACTION", 3)
        assert par.get_param_int("FS_ACTION") == 3 and v.cfg_mav.fs_action == 3
        with pytest.raises(Exception):  # noqa: B017 MAVSDK's ParamError: the echo is not the value sent
            par.set_param_float("LOIT_RADIUS", 1e6)
        assert v.cfg_mav.loiter_radius_m == 2.0
        t_end = time.monotonic() + 5.0
        while time.monotonic() < t_end and json.loads((v.run_dir / "params.json").read_text())["WP_RADIUS"] != 4.5:
            time.sleep(0.05)
        assert json.loads((v.run_dir / "params.json").read_text())["WP_RADIUS"] == 4.5
    finally:
        v.stop()
