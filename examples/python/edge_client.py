#!/usr/bin/env python3
"""A program in another language on MRT's robots' network, through `mrt edge`: reads a robot's
world snapshots (as JSON, and in the MRT manual's XML self-describing form) and sends that
robot a command, a new behavior file (`BehaviorPush`), then waits for its answer.

    pip install eclipse-zenoh==1.10.2
    mrt sim --distributed --home chaos        # prints: network of this match: .../monitor.cfg
    mrt edge --net .../monitor.cfg            # prints: edge ready: listening on tcp/127.0.0.1:P ...
    python3 examples/python/edge_client.py --connect tcp/127.0.0.1:P --robot 2

Prints one JSON line {"snapshots": N, "time": S, "pose": [x, y, theta], "xml_objects": K,
"ball_reliability": R, "installed": true, "reloaded": [...]} and exits 0 when the robot took the behavior, 1 when it did not or was
silent, 3 when the zenoh package is missing.
"""
import argparse
import json
import xml.etree.ElementTree as ET
import sys
import threading
import time

try:
    import zenoh
except ImportError as e:  # the caller may skip the example
    print(f"missing Python package: {e.name} (pip install eclipse-zenoh)", file=sys.stderr)
    sys.exit(3)

# The behavior sent: the TeamChaos `stand` behavior (stay, watch the ball), with a comment.
STAND = """-- stand, sent by examples/python/edge_client.py
always("go", "STAY")
always("turn", "NONE")
always("strafe", "NONE")
need(1, BALL)
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--connect", required=True, help="the edge's endpoint, tcp/127.0.0.1:PORT")
    ap.add_argument("--robot", type=int, default=2, help="the robot's Agora id")
    ap.add_argument("--snapshots", type=int, default=3, help="world snapshots to read first")
    ap.add_argument("--timeout", type=float, default=20.0, help="seconds to wait for each step")
    args = ap.parse_args()

    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("connect/endpoints", json.dumps([args.connect]))
    conf.insert_json5("listen/endpoints", "[]")
    conf.insert_json5("scouting/multicast/enabled", "false")
    conf.insert_json5("scouting/gossip/enabled", "false")
    session = zenoh.open(conf)

    snapshots, replies, described = [], [], []
    got = threading.Condition()

    def on_snapshot(sample):
        with got:
            snapshots.append(json.loads(sample.payload.to_bytes()))
            got.notify_all()

    def on_xml(sample):
        # The manual's self-describing form: objects with a class, attributes with a value
        # (or a symbol), a variability and a reliability.
        with got:
            described.append(ET.fromstring(sample.payload.to_bytes()))
            got.notify_all()

    def on_reply(sample):
        with got:
            replies.append(json.loads(sample.payload.to_bytes()))
            got.notify_all()

    robot = args.robot
    subs = [
        session.declare_subscriber(f"mrt/json/{robot}/WorldSnapshot", on_snapshot),
        session.declare_subscriber(f"mrt/json/{robot}/BehaviorPushReply", on_reply),
        session.declare_subscriber(f"mrt/xml/{robot}/WorldSnapshot", on_xml),
    ]

    with got:
        if not got.wait_for(lambda: len(snapshots) >= args.snapshots and described, args.timeout):
            print(f"robot {robot}: {len(snapshots)} world snapshots in {args.timeout} s", file=sys.stderr)
            return 1
        last = snapshots[-1]
        form = described[-1]
    ball = form.find("object[@name='global_ball.pose']")
    reliability = None
    if ball is not None:
        x = ball.find("attribute[@name='x']")
        reliability = None if x is None else float(x.get("reliability"))
    # Time in nanoseconds of the robot's clock; the pose in the robot's team frame, m and rad.
    pose = (last.get("my_pos") or {}).get("pose") or {}

    request = int(time.time() * 1000) & 0xFFFFFFFF
    push = {"robot": robot, "request": request, "file": "stand.lua", "source": STAND}
    session.put("mrt/json-in/BehaviorPush", json.dumps(push))
    with got:
        ok = got.wait_for(lambda: any(r.get("request") == request for r in replies), args.timeout)
        reply = next((r for r in replies if r.get("request") == request), None)
    if not ok or reply is None:
        print(f"robot {robot}: no answer to the push in {args.timeout} s", file=sys.stderr)
        return 1
    print(json.dumps({
        "snapshots": len(snapshots),
        "time": (last.get("time") or 0) / 1e9,
        "pose": [pose.get("x"), pose.get("y"), pose.get("theta")],
        "xml_objects": len(form.findall("object")),
        "ball_reliability": reliability,
        "installed": reply.get("installed"),
        "reloaded": reply.get("reloaded"),
        "error": reply.get("error"),
    }))
    for s in subs:
        s.undeclare()
    session.close()
    return 0 if reply.get("installed") else 1


if __name__ == "__main__":
    sys.exit(main())
