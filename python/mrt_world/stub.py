"""The stub world: synthetic readings for MRT robots, to run a robot without a simulator.

    python -m mrt_world.stub --world stub --robot home-1 --steps 100 --listen tcp/127.0.0.1:7470

Each step every robot reads: the game playing (attack 1), the odometry of a robot driving
slowly straight forward (mice D = 0.2 m apart, a differential base with wheels of radius
0.05 m), 16 sonars in a ring and a 320x240 image of green carpet with a white line. Steps are
lock-step: ``--period`` is the world time between two steps, not a wait. ``--hostile`` also puts,
between the regular steps, messages a correct robot must drop unanswered.

Prints one JSON line on stdout (the summary); exits 0 when every robot answered every step
(and no hostile message) and said bye, 1 otherwise. Diagnostics go to stderr.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence

import numpy as np

from .protocol import PROTOCOL, camera, encode, game, jpeg_image, odometry, rgb8_image, sense, sonar
from .world import World

SPEED = 0.1  # m/s forward
WHEEL_RADIUS = 0.05  # m
SONARS = 16
WIDTH, HEIGHT = 320, 240
CARPET, LINE = (30, 130, 50), (255, 255, 255)
BIG = 40 * 1024 * 1024


def log(*parts: object) -> None:
    """Progress and diagnostics, on stderr."""
    print("mrt_world.stub:", *parts, file=sys.stderr, flush=True)


def picture() -> np.ndarray:
    """The carpet with one white line across it, (HEIGHT, WIDTH, 3) uint8."""
    image = np.empty((HEIGHT, WIDTH, 3), np.uint8)
    image[:] = CARPET
    image[170:176, :] = LINE
    return image


def readings(step: int, time: float, period: float, image: dict | None, pan: float | None) -> dict:
    """The synthetic sense of one robot at ``step``."""
    d = SPEED * period if step > 0 else 0.0  # the motion since the previous step
    # Straight ahead: each mouse moves d longitudinally (ȳ) and 0 laterally (x̄), at any D.
    odo = odometry(mice=(0.0, d, 0.0, d), wheels=[d / WHEEL_RADIUS, d / WHEEL_RADIUS])
    sonars = [sonar(2 * math.pi * i / SONARS, 3.0 if i % 2 == 0 else None) for i in range(SONARS)]
    cam = None if image is None else camera(time, image, pan=0.0 if pan is None else pan)
    return sense(step, time, game("playing", 1), odometry=odo, camera=cam, sonars=sonars)


def hostile(world: World, robot: str, period: float, big: bool) -> None:
    """Put on ``robot``'s sense key messages a correct robot drops without answering."""
    k, t = world.steps - 1, world.time or 0.0
    header = {"protocol": PROTOCOL, "world": world.name, "run": world.run, "robot": robot}
    good = {**header, **readings(k + 1, t + period, period, None, None)}
    bad = [
        b"\xff{this is not JSON",
        {**good, "protocol": 2},
        {**good, "run": "not-" + world.run},
        {**good, "robot": "intruder"},
        {**good, "time": t - period / 2},  # backwards
        {**good, "time": t + 1000.0},  # a jump
        {
            **good,
            "camera": camera(
                t + period, {"width": WIDTH, "height": HEIGHT, "encoding": "rgb8", "data": "AAAA"}
            ),
        },
    ]
    if k >= 1:
        bad.append({**header, **readings(k - 1, t - period, period, None, None)})  # an old step
    if big:
        bad.append(encode({**good, "padding": "x" * BIG}))
    for message in bad:
        world.put_sense_bytes(robot, message if isinstance(message, bytes) else encode(message))


def main(argv: Sequence[str] | None = None) -> int:
    """Run the stub world; returns the exit code."""
    p = argparse.ArgumentParser(prog="python -m mrt_world.stub", description=__doc__.split("\n")[0])
    p.add_argument("--world", default="stub", help="the world's name (default stub)")
    p.add_argument("--robot", action="append", required=True, help="a robot's name (repeat for more)")
    p.add_argument("--steps", type=int, default=100, help="steps to run (default 100)")
    p.add_argument("--listen", action="append", help="a zenoh endpoint to listen on, e.g. tcp/127.0.0.1:7470")
    p.add_argument("--connect", action="append", help="a zenoh endpoint to connect to")
    p.add_argument("--period", type=float, default=0.1, help="world time between steps, s (default 0.1)")
    p.add_argument(
        "--image", choices=("rgb8", "jpeg", "none"), default="rgb8", help="camera images (default rgb8)"
    )
    p.add_argument(
        "--timeout", type=float, default=20.0, help="s to wait for the robots' tokens (default 20)"
    )
    p.add_argument("--step-timeout", type=float, default=5.0, help="s to wait for a step's acts (default 5)")
    p.add_argument("--hostile", action="store_true", help="put bad messages between the regular steps")
    args = p.parse_args(argv)
    if args.steps < 0 or not 0 < args.period <= 10:
        p.error("--steps must be >= 0 and --period in (0, 10]")

    image = None
    if args.image == "rgb8":
        image = rgb8_image(WIDTH, HEIGHT, picture())
    elif args.image == "jpeg":
        image = jpeg_image(picture())
    robots = args.robot
    answered = dict.fromkeys(robots, 0)
    faults: dict[str, list[str]] = {r: [] for r in robots}
    answered_hostile = dict.fromkeys(robots, 0)
    byes: dict = dict.fromkeys(robots)
    steps = 0
    with World(args.world, robots, listen=args.listen, connect=args.connect) as world:
        log(f"world {world.name} run {world.run}: waiting for {', '.join(robots)}")
        try:
            world.wait_for_robots(args.timeout)
        except TimeoutError as e:
            log(e)
        else:
            for k in range(args.steps):
                t = k * args.period
                senses = {r: readings(k, t, args.period, image, world.command(r).pan) for r in robots}
                acts = world.step(senses, timeout=args.step_timeout)
                steps += 1
                for robot, act in acts.items():
                    if act is None:
                        log(f"step {k}: no answer from {robot}")
                        continue
                    answered[robot] += 1
                    for fault in act["faults"]:
                        if fault not in faults[robot] and len(faults[robot]) < 100:
                            faults[robot].append(fault)
                if args.hostile and k + 1 < args.steps:
                    for robot in robots:
                        hostile(world, robot, args.period, big=k == 1)
                    for robot, reason in world.drain(0.05):
                        if reason in ("duplicate", "late"):  # a resent step's second answer
                            continue
                        log(f"step {k}: {robot} answered a hostile message ({reason})")
                        answered_hostile[robot] += 1
                if k % 100 == 0:
                    log(f"step {k}")
            byes = world.end()
        dropped = dict(world.dropped)
    summary = {
        "steps": steps,
        "answered": answered,
        "missing": {r: args.steps - answered[r] for r in robots},
        "faults": faults,
        "dropped": dropped,
        "byes": {r: byes[r] is not None for r in robots},
    }
    if args.hostile:
        summary["answered_hostile"] = answered_hostile
    print(json.dumps(summary), flush=True)
    ok = all(summary["missing"][r] == 0 and summary["byes"][r] and answered_hostile[r] == 0 for r in robots)
    return 0 if ok and steps == args.steps else 1


if __name__ == "__main__":
    sys.exit(main())
