#!/usr/bin/env python3
"""A playable MuJoCo world: MRT robots (`mrt robot --config FILE`) play on the MuJoCo field over
the device protocol (docs/devices.md), lock-step.

    MUJOCO_GL=egl python worlds/mujoco/world.py play --scene scenes/bright.xml \\
        --camera configs/vision/camera.toml --home 1 --away 0 --listen tcp/127.0.0.1:7470 \\
        [--world mujoco] [--half 300] [--seed S] [--scenario match|empty-goal] \\
        [--truth FILE.jsonl] [--step-timeout 10] [--image jpeg|rgb8]

Each step (STEP = 0.1 s, the robots' control period) every robot gets its sense: the motion of
its encoders and mice over the previous step (from its body's actual motion), its front
camera's image (rendered from its pose, its pan joint and its camera file, its own body not
drawn), its 16 sonars and the game controller's news; the world waits for every act, applies
wheels, kick and pan, and advances the physics (MuJoCo steps of the scene's timestep) by STEP.
physics.py has the bodies and sensors, referee.py the rules.

Scenarios: `match` (home-1..home-N against away-1..away-M, two halves of --half s of play),
`empty-goal` (home-1 alone, at a seeded random pose, the ball at a seeded random spot at least
1 m away; play at once; ends at the first goal or after 60 s of play).

At the end it prints ONE JSON line on stdout (the summary); progress goes to stderr.
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import os
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
sys.path.insert(0, str(HERE))
try:
    import mrt_world  # noqa: F401
except ImportError:
    sys.path.insert(0, str(REPO / "python"))

import numpy as np  # noqa: E402

import physics  # noqa: E402
import render_frames as rf  # noqa: E402
from mrt_world import (  # noqa: E402
    World, camera, game, jpeg_image, odometry, pose, rgb8_image, sense, sonar,
)
from referee import LENGTH, WIDTH, Referee  # noqa: E402

STEP = 0.1  # s: one step, the robots' control period
EMPTY_GOAL_TIME = 60.0  # s of play in the empty-goal scenario
PROGRESS_EVERY = 10.0  # s of play between two progress lines


def log(*parts: object) -> None:
    print("world.py:", *parts, file=sys.stderr, flush=True)


class Match:
    """The physics, the cameras and the referee of one match (no network: :func:`play` and the
    tests drive it)."""

    def __init__(self, scene, camera_file, home: int, away: int, scenario: str = "match",
                 half: float = 300.0, seed: int = 0, image: str = "jpeg",
                 render: bool = True, placed: bool = True, shadows: bool = True,
                 samples: int | None = None) -> None:
        if scenario not in ("match", "empty-goal"):
            raise ValueError(f"scenario must be match or empty-goal, not {scenario!r}")
        if scenario == "empty-goal":
            home, away = 1, 0
        if home + away < 1:
            raise ValueError("a match needs a robot")
        self.scenario, self.seed, self.image, self.tell_placed = scenario, seed, image, placed
        self.camera = rf.Camera.load(camera_file)
        self.names = [n for n, _, _ in physics.robot_names(home, away)]
        drive = physics.edit_scene(home, away)

        def edit(spec):
            drive(spec)
            if samples is not None:  # multisample anti-aliasing of the offscreen frames
                spec.visual.quality.offsamples = samples

        if render:
            self.view = rf.World(scene, self.camera, edit=edit)
            if not shadows:
                self.view.renderer.scene.flags[self.view.mj.mjtRndFlag.mjRND_SHADOW] = 0
            model, data = self.view.model, self.view.data
        else:
            self.view = None
            model, data = physics.compile_scene(scene, home, away)
        self.physics = physics.Physics(model, data, home, away, pan=self.camera.pan)
        if scenario == "empty-goal":
            self.referee = Referee(self.names, half=EMPTY_GOAL_TIME, halves=1, start="playing",
                                   until_goal=True)
            start, ball = self._empty_goal_start(np.random.default_rng(seed))
        else:
            self.referee = Referee(self.names, half=half, halves=2)
            start, ball = self.referee.entry_poses(), (0.0, 0.0)
        for name, p in start.items():
            self.physics.place_robot(name, p)
        self.physics.place_ball(*ball)
        self.odometers = {n: physics.Odometer(self.physics.pose(n)) for n in self.names}
        # A robot put down by hand (at the start, or by the referee) is told where.
        self.placed = {n: p for n, p in start.items()} if placed else {}
        self.time = 0.0
        self.steps = 0
        self.render_seconds: list[float] = []
        self.kicks = 0

    def _empty_goal_start(self, rng):
        hl, hw, m = LENGTH / 2 - 0.5, WIDTH / 2 - 0.5, 0.5
        x, y = rng.uniform(-hl, hl), rng.uniform(-hw, hw)
        robot = (float(x), float(y), float(rng.uniform(-math.pi, math.pi)))
        while True:
            bx, by = rng.uniform(-hl + m, hl - m), rng.uniform(-hw + m, hw - m)
            if math.hypot(bx - x, by - y) >= 1.0:
                return {"home-1": robot}, (float(bx), float(by))

    # ------------------------------------------------------------ sensing

    def frame(self, name: str) -> np.ndarray:
        """What robot `name`'s front camera sees now (height x width x 3, uint8): the camera
        file's intrinsics and mounting, turned by the pan joint, the robot's own body hidden."""
        mj, view = self.physics.mj, self.view
        r = self.physics.robots[name]
        cam = copy.copy(self.camera)
        cam.pan = r.pan  # the joint's angle replaces the file's pan_deg (as the robot reads it)
        p = self.physics.pose(name)
        data = self.physics.data
        data.mocap_pos[view.viewer] = cam.centre(p)
        data.mocap_quat[view.viewer] = cam.mujoco_quat(p)
        mj.mj_kinematics(self.physics.model, data)
        mj.mj_camlight(self.physics.model, data)  # the camera follows its body
        groups = self.physics.model.geom_group
        for g in r.geoms:
            groups[g] = rf.HIDDEN_GROUP
        try:
            img = view.render()
        finally:
            for g in r.geoms:
                groups[g] = 0
        self.render_seconds.append(view.render_seconds[-1])
        return img

    def sense(self, name: str) -> dict:
        """Robot `name`'s readings now (and its odometry since the previous call)."""
        ph = self.physics
        mice, wheels = self.odometers[name].read(ph.pose(name))
        at = self.placed.pop(name, None)
        odo = odometry(mice=mice, wheels=wheels, placed=None if at is None else pose(*at))
        cam = None
        if self.view is not None:
            img = self.frame(name)
            if self.image == "rgb8":
                data = rgb8_image(img.shape[1], img.shape[0], img)
            else:
                data = jpeg_image(img, quality=90)
            cam = camera(self.time, data, pan=ph.robots[name].pan)
        sonars = [sonar(b, r) for b, r in ph.sonars(name)]
        state, attack, kickoff, marker = self.referee.game(name)
        g = game(state, attack, None if kickoff is None else pose(*kickoff), marker)
        return sense(self.steps, self.time, g, odometry=odo, camera=cam, sonars=sonars)

    def senses(self) -> dict[str, dict]:
        return {n: self.sense(n) for n in self.names}

    # ------------------------------------------------------------ acting and time

    def act(self, name: str, wheels=None, pan=None, kick: bool = False) -> None:
        """Applies one robot's command (wheel set-points rad/s, pan set-point rad, kick).
        The kicker fires only in play."""
        self.physics.command(name, wheels, pan)
        if kick and self.referee.state == "playing" and self.physics.kick(name):
            self.kicks += 1

    def advance(self) -> list[str]:
        """One step of physics, then the referee; returns the referee's calls."""
        ph = self.physics
        ph.step(STEP)
        self.steps += 1
        self.time = round(self.steps * STEP, 9)
        ball = ph.ball()
        poses = {n: ph.pose(n) for n in self.names}
        d = self.referee.update(self.time, STEP, ball, poses)
        if d.ball is not None:
            ph.place_ball(*d.ball)
        for name, p in d.robots.items():
            ph.place_robot(name, p)
            self.odometers[name] = physics.Odometer(ph.pose(name))
            if self.tell_placed:
                self.placed[name] = p
        return d.calls

    def truth(self) -> dict:
        bx, by, vx, vy = self.physics.ball()
        robots = {}
        for n in self.names:
            x, y, t = self.physics.pose(n)
            robots[n] = [round(x, 4), round(y, 4), round(math.remainder(t, 2 * math.pi), 4)]
        return {"time": round(self.time, 3), "state": self.referee.state,
                "score": dict(self.referee.score),
                "ball": [round(bx, 4), round(by, 4), round(vx, 4), round(vy, 4)],
                "robots": robots}

    def close(self) -> None:
        if self.view is not None:
            self.view.renderer.close()


# --- play -------------------------------------------------------------------------------------


def play(args) -> dict:
    """Plays the match `args` (main's options) with the robots over zenoh; returns the summary."""
    m = Match(rf.find(args.scene, HERE), rf.find(args.camera, REPO), args.home, args.away,
              args.scenario, args.half, args.seed, args.image, placed=not args.no_placed,
              shadows=not args.no_shadows, samples=args.samples)
    truth = open(args.truth, "w") if args.truth else None
    acts_log = open(args.acts, "w") if args.acts else None
    answered = dict.fromkeys(m.names, 0)
    byes: dict = {}
    frames = Path(args.save_frames) if args.save_frames else None
    if frames:
        frames.mkdir(parents=True, exist_ok=True)
    log(f"{args.scenario}: {', '.join(m.names)} on {Path(args.scene).name}; world "
        f"{args.world!r} listening on {args.listen}; waiting for the robots")
    with World(args.world, m.names, listen=[args.listen]) as world:
        world.wait_for_robots(timeout=args.wait)
        log("all robots are here")
        started = time.perf_counter()
        next_progress = PROGRESS_EVERY
        try:
            while True:
                last = m.referee.state == "finished"
                senses = m.senses()
                if frames and m.steps % args.frame_every == 0:
                    _save_frames(m, senses, frames)
                if truth:
                    truth.write(json.dumps(m.truth()) + "\n")
                acts = world.step(senses, timeout=args.step_timeout)
                if acts_log:
                    keep = ("wheels", "twist", "kick", "pan", "faults")
                    acts_log.write(json.dumps({"step": world.steps - 1, "time": m.time, "acts": {
                        n: a and {k: a[k] for k in keep} for n, a in acts.items()}}) + "\n")
                for name, act in acts.items():
                    if act is None:
                        log(f"step {m.steps}: no answer from {name}")
                    else:
                        answered[name] += 1
                        for fault in act["faults"]:
                            log(f"step {m.steps}: {name}: {fault}")
                if last or (args.steps and world.steps >= args.steps):
                    break
                for name in m.names:
                    c = world.command(name)
                    m.act(name, c.wheels, c.pan, c.kick)
                for call in m.advance():
                    log(f"t={m.time:.1f}: {call}")
                if m.referee.play_time + 1e-9 >= next_progress:
                    next_progress += PROGRESS_EVERY
                    _progress(m, started)
        except KeyboardInterrupt:
            log("interrupted: ending the match")
        wall = time.perf_counter() - started
        byes = world.end()
    for f in (truth, acts_log):
        if f:
            f.close()
    m.close()
    summary = {
        "world": args.world,
        "scenario": args.scenario,
        "seed": args.seed,
        "steps": world.steps,
        "play_time": round(m.referee.play_time, 3),
        "score": dict(m.referee.score),
        "goals": [{"team": g["team"], "time": g["time"]} for g in m.referee.goals],
        "answered": answered,
        "missing": {n: world.steps - answered[n] for n in m.names},
        "render_ms": (round(1000 * float(np.mean(m.render_seconds)), 2)
                      if m.render_seconds else None),
        "real_time_factor": round(m.time / wall, 3) if wall > 0 else None,
        "byes": {n: byes.get(n) is not None for n in m.names},
    }
    return summary


def _progress(m: Match, started: float) -> None:
    ref = m.referee
    bx, by, _, _ = m.physics.ball()
    ms = 1000 * float(np.mean(m.render_seconds[-100:])) if m.render_seconds else 0.0
    rtf = m.time / max(time.perf_counter() - started, 1e-9)
    log(f"play {ref.play_time:.0f} s (half {ref.half}, t={m.time:.1f} s, {ref.state}): "
        f"{ref.score['home']}:{ref.score['away']}, ball ({bx:.2f}, {by:.2f}), "
        f"render {ms:.0f} ms a frame, {rtf:.2f} x real time")


def _save_frames(m: Match, senses: dict, out: Path) -> None:
    """The images just sent, as PNGs (for looking at what the robots see)."""
    import base64
    import io

    from PIL import Image

    for name, s in senses.items():
        image = (s.get("camera") or {}).get("image")
        if not image:
            continue
        data = base64.b64decode(image["data"])
        if image["encoding"] == "jpeg":
            img = Image.open(io.BytesIO(data))
        else:
            img = Image.frombytes("RGB", (image["width"], image["height"]), data)
        img.save(out / f"{name}_{m.steps:05d}.png")


def parser() -> argparse.ArgumentParser:
    """The command line (`play` and its options)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n".join(__doc__.splitlines()[1:]))
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("play", help="play a match (or a scenario) with MRT robots")
    p.add_argument("--scene", default="scenes/bright.xml",
                   help="a scene file (relative paths also tried from worlds/mujoco/)")
    p.add_argument("--camera", default="configs/vision/camera.toml",
                   help="the robots' camera file (relative paths also tried from the "
                        "repository's root)")
    p.add_argument("--home", type=int, default=1, help="home robots: home-1 .. home-N")
    p.add_argument("--away", type=int, default=0, help="away robots: away-1 .. away-M")
    p.add_argument("--listen", required=True, help="zenoh endpoint, e.g. tcp/127.0.0.1:7470")
    p.add_argument("--world", default="mujoco", help="the world's name in the keys")
    p.add_argument("--half", type=float, default=300.0, help="s of play a half (match)")
    p.add_argument("--seed", type=int, default=0, help="the scenario's random placement")
    p.add_argument("--scenario", choices=("match", "empty-goal"), default="match")
    p.add_argument("--truth", help="write the truth, one JSON line a step, to this file")
    p.add_argument("--acts", help="write the robots' acts, one JSON line a step, to this file")
    p.add_argument("--step-timeout", type=float, default=10.0,
                   help="s to wait for each step's acts (then the safe command holds)")
    p.add_argument("--wait", type=float, default=60.0, help="s to wait for the robots")
    p.add_argument("--image", choices=("jpeg", "rgb8"), default="jpeg",
                   help="the camera images' encoding (jpeg: quality 90)")
    p.add_argument("--no-placed", action="store_true",
                   help="never tell a robot where it was put down (it must find itself)")
    p.add_argument("--no-shadows", action="store_true",
                   help="draw no shadows (renders several times faster)")
    p.add_argument("--samples", type=int, metavar="N",
                   help="multisample anti-aliasing of the images, samples a pixel (0: off; "
                        "default: the scene's, MuJoCo's 4)")
    p.add_argument("--steps", type=int, default=0,
                   help="end after this many steps whatever the game (0: when it is over)")
    p.add_argument("--save-frames", metavar="DIR", help="save the images sent, as PNGs")
    p.add_argument("--frame-every", type=int, default=10, metavar="K",
                   help="with --save-frames: every K-th step (default %(default)s)")
    return ap


def main(argv=None) -> int:
    if "MUJOCO_GL" not in os.environ and not os.environ.get("DISPLAY"):
        os.environ["MUJOCO_GL"] = "egl"
    args = parser().parse_args(argv)
    if args.scenario == "empty-goal":
        if (args.home, args.away) != (1, 0):
            log("empty-goal plays home-1 alone: --home and --away are ignored")
        args.home, args.away = 1, 0
    summary = play(args)
    print(json.dumps(summary), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
