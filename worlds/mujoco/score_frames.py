#!/usr/bin/env python3
"""Scores what `mrt vision detect` found in a dataset of rendered frames against its truth.

    python render_frames.py dataset --scene scenes/side.xml --camera configs/vision/camera.toml \\
        --count 60 --empty 5 --robots 2 --seed 204 --out frames/side
    mrt vision detect --camera configs/vision/camera.toml --colors configs/vision/colors.toml \\
        frames/side/ > frames/side/detect.jsonl
    python score_frames.py frames/side frames/side/detect.jsonl --camera configs/vision/camera.toml

Prints one JSON object:
- the ball: how many frames with a ball it was found in, its range error (relative, %) and
  bearing error (degrees), and balls reported in frames without one;
- the nets (the centres of the goal lines, east the yellow goal): those wholly in view (both
  posts' feet in the image, at most NET_RANGE m away), those reported and their errors, and
  those reported of a goal not wholly in view;
- the other robots: those in view (their nearest point on the floor inside the image, at most
  RANGE m away); those found (a robot reported within BEARING_MATCH degrees and DISTANCE_MATCH
  of the distance of one of them; one whose nearest point is out of view, found by its bearing
  alone, is not scored), with the error of their nearest point's distance (%) and bearing
  (degrees) and their markers (right, wrong, none: home wears magenta, away cyan); the
  misplaced (reported within BEARING_MATCH of a robot but not within DISTANCE_MATCH of its
  distance: a robot half hidden, or split in two); and phantoms (reported where no robot of
  the truth stands within BEARING_MATCH, in view or not).

A robot is a disc of ROBOT_RADIUS m: its nearest point lies that much closer than its centre.
Needs numpy, not MuJoCo.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import render_frames as rf  # noqa: E402

ROBOT_RADIUS = 0.25  # m, the field's robots (robots/*.xml)
HALF_LENGTH, GOAL_HALF_WIDTH = 9.0, 1.0  # m: the goal lines' x, the posts' y (field.xml)
NET_RANGE = 25.0  # m: a net farther away is not counted as in view (as mrt vision survey)
RANGE = 7.0  # m: how far the vision tells robots (mrt_robot::config::VISION_ROBOT_RANGE)
BEARING_MATCH = 10.0  # degrees
DISTANCE_MATCH = 0.3  # of the true distance
MARKERS = {"home": "magenta", "away": "cyan"}
MARGIN_PX = 2.0  # a nearest point this close to the image's edge is not counted as in view


def spread(errors: list[float]) -> dict | None:
    """Mean, median, 90th percentile and worst of some errors (None when there are none)."""
    if not errors:
        return None
    a = np.sort(np.asarray(errors, dtype=float))
    rank = lambda q: float(a[math.floor((len(a) - 1) * q + 0.5)])  # noqa: E731  nearest rank
    return {"count": len(a), "mean": round(float(a.mean()), 3), "median": round(rank(0.5), 3),
            "p90": round(rank(0.9), 3), "worst": round(float(a[-1]), 3)}


def relative(pose, x, y):
    """(distance, bearing rad) of field point (x, y) from a robot at `pose`, robot axes."""
    px, py, h = pose
    dx, dy = x - px, y - py
    rx = math.cos(h) * dx + math.sin(h) * dy
    ry = -math.sin(h) * dx + math.cos(h) * dy
    return math.hypot(rx, ry), math.atan2(ry, rx)


def in_image(camera: rf.Camera, pose, x: float, y: float) -> bool:
    """Whether the floor point (x, y) shows in the camera's image from `pose`."""
    uv, z = camera.project(pose, np.array([[x, y, 0.0]]))
    u, v = uv[0]
    return bool(z[0] > 0 and MARGIN_PX <= u <= camera.width - MARGIN_PX
                and MARGIN_PX <= v <= camera.height - MARGIN_PX)


def robots_seen_from(camera: rf.Camera, truth: dict) -> list[dict]:
    """The truth's robots as the camera's robot sees them: each one's nearest floor point's
    distance (from the point under the camera) and bearing, its team, and whether it is in
    view (the camera images that point, at most RANGE away)."""
    pose = truth["camera_pose"]
    fx, fy = camera.foot(pose)
    out = []
    for x, y, team in truth.get("robots", []):
        d, b = relative((fx, fy, pose[2]), x, y)
        near = d - ROBOT_RADIUS
        view = 0.0 < near <= RANGE
        if view:
            # The nearest point on the floor, towards the camera.
            nx, ny = x - (x - fx) / d * ROBOT_RADIUS, y - (y - fy) / d * ROBOT_RADIUS
            view = in_image(camera, pose, nx, ny)
        out.append({"distance": near, "bearing": b, "team": team, "in_view": view})
    return out


def nets_seen_from(camera: rf.Camera, truth: dict) -> dict[str, dict]:
    """The east and the west net (the centres of the goal lines) as the camera's robot sees
    them: distance, bearing, and whether the goal is wholly in view (both posts' feet in the
    image, at most NET_RANGE away)."""
    pose = truth["camera_pose"]
    fx, fy = camera.foot(pose)
    out = {}
    for goal, x in (("east", HALF_LENGTH), ("west", -HALF_LENGTH)):
        d, b = relative((fx, fy, pose[2]), x, 0.0)
        view = d <= NET_RANGE and all(in_image(camera, pose, x, y)
                                      for y in (GOAL_HALF_WIDTH, -GOAL_HALF_WIDTH))
        out[goal] = {"distance": d, "bearing": b, "in_view": view}
    return out


def score(camera: rf.Camera, truths: list[dict], detections: dict[str, list[dict]]) -> dict:
    """The scores (module doc) of `detections` (objects by frame file name) against `truths`."""
    ball_range, ball_bearing, with_ball, found, false_balls, empty = [], [], 0, 0, 0, 0
    robot_range, robot_bearing = [], []
    in_view = matched = misplaced = phantoms = 0
    markers = {"right": 0, "wrong": 0, "none": 0}
    net_range, net_bearing, nets_in_view, nets_found, nets_unseen = [], [], 0, 0, 0
    for t in truths:
        objects = detections.get(t["file"], [])
        nets = nets_seen_from(camera, t)
        nets_in_view += sum(n["in_view"] for n in nets.values())
        for o in (o for o in objects if o.get("class") == "net"):
            n = nets.get(o.get("goal"))
            if n is None or not n["in_view"]:
                nets_unseen += 1
                continue
            nets_found += 1
            net_range.append(100 * abs(o["distance_m"] - n["distance"]) / n["distance"])
            err = math.remainder(math.radians(o["bearing_deg"]) - n["bearing"], math.tau)
            net_bearing.append(abs(math.degrees(err)))
        balls = [o for o in objects if o.get("class") == "ball"]
        if t.get("distance") is not None:
            with_ball += 1
            if balls:
                found += 1
                b = balls[0]
                ball_range.append(100 * abs(b["distance_m"] - t["distance"]) / t["distance"])
                err = math.remainder(math.radians(b["bearing_deg"]) - t["bearing"], math.tau)
                ball_bearing.append(abs(math.degrees(err)))
        else:
            empty += 1
            false_balls += len(balls)
        everyone = robots_seen_from(camera, t)
        in_view += sum(r["in_view"] for r in everyone)
        taken: set[int] = set()
        for o in (o for o in objects if o.get("class") == "robot"):
            bearing = math.radians(o["bearing_deg"])

            def off(r):
                return abs(math.degrees(math.remainder(bearing - r["bearing"], math.tau)))

            def near(r):  # a robot cut by the image's edge is matched by its bearing alone
                far = abs(o["distance_m"] - r["distance"]) > DISTANCE_MATCH * r["distance"]
                return off(r) <= BEARING_MATCH and not (r["in_view"] and far)

            close = [(off(r), k) for k, r in enumerate(everyone) if k not in taken and near(r)]
            if not close:
                if any(off(r) <= BEARING_MATCH for r in everyone):
                    misplaced += 1  # where a robot stands, at the wrong distance
                else:
                    phantoms += 1
                continue
            _, k = min(close)
            taken.add(k)
            r = everyone[k]
            if not r["in_view"]:
                continue  # a robot whose nearest point is out of view, found anyway: not scored
            matched += 1
            robot_range.append(100 * abs(o["distance_m"] - r["distance"]) / r["distance"])
            robot_bearing.append(off(r))
            marker = o.get("marker")
            key = "none" if marker is None else "right" if marker == MARKERS[r["team"]] else "wrong"
            markers[key] += 1
    return {
        "frames": len(truths),
        "ball": {"frames_with_ball": with_ball, "found": found,
                 "range_error_pct": spread(ball_range), "bearing_error_deg": spread(ball_bearing),
                 "empty_frames": empty, "balls_in_empty_frames": false_balls},
        "nets": {"in_view": nets_in_view, "found": nets_found,
                 "distance_error_pct": spread(net_range), "bearing_error_deg": spread(net_bearing),
                 "not_wholly_in_view": nets_unseen},
        "robots": {"in_view": in_view, "found": matched,
                   "distance_error_pct": spread(robot_range),
                   "bearing_error_deg": spread(robot_bearing),
                   "markers": markers, "misplaced": misplaced, "phantoms": phantoms},
    }


def read_truths(dataset: Path) -> list[dict]:
    with open(dataset / "truth.jsonl") as fh:
        return [json.loads(line) for line in fh if line.strip()]


def read_detections(path: Path) -> dict[str, list[dict]]:
    out = {}
    with open(path) as fh:
        for line in fh:
            if line.strip():
                d = json.loads(line)
                out[Path(d["image"]).name] = d.get("objects", [])
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("dataset", type=Path, help="the dataset's directory (with truth.jsonl)")
    p.add_argument("detections", type=Path, help="mrt vision detect's output on it (JSON lines)")
    p.add_argument("--camera", default="configs/vision/camera.toml",
                   help="the camera file the frames were rendered through")
    args = p.parse_args(argv)
    try:
        camera = rf.Camera.load(rf.find(args.camera, rf.REPO))
        result = score(camera, read_truths(args.dataset), read_detections(args.detections))
    except (OSError, ValueError, KeyError) as e:
        print(f"score_frames.py: {e}", file=sys.stderr)
        return 1
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
