"""The live Foxglove WebSocket stream of ``oceangnc mavlink --foxglove`` (issue 31; docs/view.md).

``oceangnc mavlink combined-survey --foxglove 0`` runs the flagship as a MAVLink vehicle and publishes
it on 127.0.0.1 with a session token (the console's rules). A WebSocket client (the ``websockets``
package) is refused without the token and with a wrong one, then subscribes with it to the vehicles'
poses and the 3D scene and reads a bounded number of live states. After the run (stopped by SIGINT,
which writes its log), the states stamped at a logged time are compared with the vehicle's own log
rows of that time: a round trip bus -> Foxglove messages -> client, checked against bus -> Parquet.
"""

from __future__ import annotations

import json
import os
import signal
import struct
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from view_helpers import first_line

ws_client = pytest.importorskip("websockets.sync.client", reason="websockets is not installed")
pytest.importorskip("pymavlink", reason="pymavlink is not installed (oceangnc[field])")

N_STATES = 60  # live states read (bounded), about 3 s of the vehicle at 1x


def _enu(n, e, d):
    return (e, n, -d)


def test_mavlink_foxglove_stream_matches_the_vehicle(tmp_path):
    out = tmp_path / "runs"
    cmd = [sys.executable, "-m", "oceangnc", "mavlink", "combined-survey", "--listen", "udp:127.0.0.1:0"]
    cmd += ["--foxglove", "0", "--no-tlog", "--quiet", "--out", str(out), "--duration", "300"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True, env=dict(os.environ, PYTHONUNBUFFERED="1"))
    refused = []
    try:
        line = first_line(proc, 180)
        assert "Foxglove WebSocket stream of the MAVLink vehicle at ws://127.0.0.1:" in line, line
        url = line.split(" at ", 1)[1].split()[0]
        assert "?token=" in url
        base, token = url.split("/?token=")
        # the console's token rules: no token, or a wrong one, is an HTTP 401 at the handshake
        for bad in (base, f"{base}/?token={token[:-1]}x"):
            with pytest.raises(ws_client.InvalidStatus) as e:
                ws_client.connect(bad, subprotocols=["foxglove.websocket.v1"], open_timeout=30)
            refused.append(e.value.response.status_code)
        with ws_client.connect(url, subprotocols=["foxglove.websocket.v1"], open_timeout=30) as ws:
            info = json.loads(ws.recv(timeout=30))
            chans = {c["topic"]: c for c in json.loads(ws.recv(timeout=30))["channels"]}
            topics = {"/usv/pose": 1, "/uuv/pose": 2, "/scene": 3}
            sub = [{"id": s, "channelId": chans[t]["id"]} for t, s in topics.items()]
            ws.send(json.dumps({"op": "subscribe", "subscriptions": sub}))
            got: dict[int, dict[int, dict]] = {1: {}, 2: {}, 3: {}}
            while len(got[3]) < N_STATES:  # bounded: N_STATES scenes, each recv at most 30 s
                frame = ws.recv(timeout=30)
                if frame[0] != 0x01:
                    continue
                sid, ts = struct.unpack("<IQ", frame[1:13])
                got[sid][ts] = json.loads(frame[13:])
    finally:
        proc.send_signal(signal.SIGINT)  # the vehicle closes its log
        try:
            proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=30)
    assert refused == [401, 401]
    assert info["op"] == "serverInfo" and "time" in info["capabilities"]
    assert chans["/uuv/pose"]["schemaName"] == "foxglove.PoseInFrame"
    assert chans["/scene"]["schemaName"] == "foxglove.SceneUpdate"
    logs = list(out.glob("mavlink-combined-survey-*/log.parquet"))
    assert len(logs) == 1, logs
    df = pd.read_parquet(logs[0])
    ns = np.round(df["t"].to_numpy() * 1e9).astype(np.int64)
    rows = {int(v): i for i, v in enumerate(ns)}
    stamps = sorted(got[3])
    assert stamps == sorted(set(stamps)) and len(stamps) == N_STATES
    matched = [ts for ts in stamps if ts in rows]
    assert len(matched) >= 10, (len(matched), stamps[:5])  # the log is 10 Hz, states 20 Hz on 0.05 s ticks
    nodes = sum(1 for c in df.columns if c.startswith("cable.x") and c[7:].isdigit())
    uuv_path = []
    for ts in matched:
        r = df.iloc[rows[ts]]
        for sid, body in ((1, "usv"), (2, "uuv")):
            p = got[sid][ts]["pose"]["position"]
            d = r.get(f"{body}.z", 0.0)  # the USV's depth is not logged: 0 (at the surface)
            assert (p["x"], p["y"], p["z"]) == _enu(r[f"{body}.x"], r[f"{body}.y"], d), (ts, body)
        cable = next(e for e in got[3][ts]["entities"] if e["id"] == "cable")["lines"][0]["points"]
        assert len(cable) == nodes
        end = cable[-1]
        k = nodes - 1
        assert (end["x"], end["y"], end["z"]) == _enu(r[f"cable.x{k}"], r[f"cable.y{k}"], r[f"cable.z{k}"])
        uuv_path.append((r["uuv.x"], r["uuv.y"], r["uuv.z"]))
    # the vehicle moved while it was streamed (the match is not of a body at rest)
    assert np.ptp(np.array(uuv_path), axis=0).max() > 1e-3


def test_token_file_and_bad_port(tmp_path, capsys):
    from oceangnc.cli import main

    assert main(["mavlink", "--token-file", str(tmp_path / "t"), "--listen", "udp:127.0.0.1:0"]) == 2
    assert "--token-file goes with --foxglove" in capsys.readouterr().err
    assert main(["mavlink", "--foxglove", "70000", "--listen", "udp:127.0.0.1:0"]) == 2
    assert "allowed range 0 <= port <= 65535" in capsys.readouterr().err
    import socket

    with socket.socket() as busy:  # a port in use
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        assert main(["mavlink", "--foxglove", str(port), "--listen", "udp:127.0.0.1:0"]) == 2
    assert f"cannot listen on 127.0.0.1:{port}" in capsys.readouterr().err
    (tmp_path / "short").write_text("abc\n")
    assert main(["mavlink", "--foxglove", "0", "--token-file", str(tmp_path / "short")]) == 2
    assert "at least 8 printable characters" in capsys.readouterr().err
