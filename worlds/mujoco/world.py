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
import contextlib
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


class UpView:
    """A robot's omnidirectional camera (an MRT omni camera file, configs/vision/
    omni-ianus3.toml): a view straight down from the mirror's viewpoint above the robot's
    centre, which images the floor as the file's affine map and a point at height z pushed out
    by viewpoint / (viewpoint - z), exactly the file's model. Beyond the mirror's reach the
    image is black."""

    CAMERA = "up_eye"
    BODY = "up_viewer"

    def __init__(self, cfg: dict) -> None:
        if cfg.get("model") != "omni":
            raise ValueError(f"an up camera file has model = \"omni\" (got {cfg.get('model')!r})")
        if float(cfg.get("rotation_deg", 0.0)) != 0.0 or cfg.get("mirrored", False):
            raise ValueError("the MuJoCo world renders up cameras with rotation_deg = 0 and "
                             "mirrored = false only")
        self.width, self.height = int(cfg["width"]), int(cfg["height"])
        self.scale = float(cfg["scale_px_per_m"])
        self.viewpoint = float(cfg.get("viewpoint_m", 0.8))
        self.range = float(cfg.get("range_m", 4.5))
        cx, cy = float(cfg["cx"]), float(cfg["cy"])
        f = self.scale * self.viewpoint
        self.camera = rf.Camera({"width": self.width, "height": self.height, "fx": f, "fy": f,
                                 "cx": cx, "cy": cy, "height_m": self.viewpoint,
                                 "tilt_deg": 90.0})
        if not self.camera.centred():
            raise ValueError("the MuJoCo world renders up cameras with cx = width / 2 and "
                             "cy = height / 2 only")
        cols, rows = np.meshgrid(np.arange(self.width) + 0.5, np.arange(self.height) + 0.5)
        self.beyond = np.hypot(cols - cx, rows - cy) / self.scale > self.range
        self.renderer = None
        self.cam_id = self.mocap = -1

    @staticmethod
    def load(path) -> "UpView":
        import tomllib

        with open(path, "rb") as fh:
            return UpView(tomllib.load(fh))

    def add_to(self, spec) -> None:
        """Adds the camera's body to the scene's MjSpec (before it is compiled)."""
        body = spec.worldbody.add_body(name=self.BODY, mocap=True)
        body.add_camera(name=self.CAMERA, fovy=self.camera.fovy_deg())

    def attach(self, mj, model) -> None:
        """Finds the camera in the compiled model and makes its renderer."""
        self.cam_id = mj.mj_name2id(model, mj.mjtObj.mjOBJ_CAMERA, self.CAMERA)
        body = mj.mj_name2id(model, mj.mjtObj.mjOBJ_BODY, self.BODY)
        self.mocap = int(model.body_mocapid[body])
        model.cam_resolution[self.cam_id] = (self.width, self.height)
        model.vis.global_.offwidth = max(model.vis.global_.offwidth, self.width)
        model.vis.global_.offheight = max(model.vis.global_.offheight, self.height)
        self.renderer = mj.Renderer(model, self.height, self.width)

    def render(self, mj, model, data, pose, option) -> np.ndarray:
        data.mocap_pos[self.mocap] = self.camera.centre(pose)
        data.mocap_quat[self.mocap] = self.camera.mujoco_quat(pose)
        mj.mj_kinematics(model, data)
        mj.mj_camlight(model, data)
        self.renderer.update_scene(data, camera=self.cam_id, scene_option=option)
        img = self.renderer.render().copy()
        img[self.beyond] = 0
        return img


class Match:
    """The physics, the cameras and the referee of one match (no network: :func:`play` and the
    tests drive it)."""

    def __init__(self, scene, camera_file, home: int, away: int, scenario: str = "match",
                 half: float = 300.0, seed: int = 0, image: str = "jpeg",
                 render: bool = True, placed: bool = True, shadows: bool = True,
                 samples: int | None = None, up_camera=None,
                 exact_odometry: bool = False) -> None:
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
        self.up = UpView.load(up_camera) if up_camera is not None and render else None

        def edit(spec):
            drive(spec)
            if self.up is not None:
                self.up.add_to(spec)
            if samples is not None:  # multisample anti-aliasing of the offscreen frames
                spec.visual.quality.offsamples = samples

        if render:
            self.view = rf.World(scene, self.camera, edit=edit)
            if self.up is not None:
                self.up.attach(self.view.mj, self.view.model)
            for r in [self.view.renderer] + ([self.up.renderer] if self.up else []):
                if not shadows:
                    r.scene.flags[self.view.mj.mjtRndFlag.mjRND_SHADOW] = 0
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
        # The sensors' errors, from a generator of their own: the same seed places the same
        # robots and ball whether the odometry is exact or not.
        self.sensor_errors = None if exact_odometry else physics.SensorErrors()
        self.sensor_rng = np.random.default_rng([seed, 1])
        self.odometers = {n: self._odometer(n) for n in self.names}
        # A robot put down by hand (at the start, or by the referee) is told where.
        self.placed = {n: p for n, p in start.items()} if placed else {}
        self.time = 0.0
        self.steps = 0
        self.render_seconds: list[float] = []
        self.up_seconds: list[float] = []

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
        with self._hidden(name):
            img = view.render()
        self.render_seconds.append(view.render_seconds[-1])
        return img

    def up_frame(self, name: str) -> np.ndarray:
        """What robot `name`'s up camera sees now, its own body hidden."""
        started = time.perf_counter()
        with self._hidden(name):
            img = self.up.render(self.physics.mj, self.physics.model, self.physics.data,
                                 self.physics.pose(name), self.view.option)
        self.up_seconds.append(time.perf_counter() - started)
        return img

    @contextlib.contextmanager
    def _hidden(self, name: str):
        """Robot `name`'s own geoms are not drawn meanwhile."""
        groups = self.physics.model.geom_group
        geoms = self.physics.robots[name].geoms
        for g in geoms:
            groups[g] = rf.HIDDEN_GROUP
        try:
            yield
        finally:
            for g in geoms:
                groups[g] = 0

    def _odometer(self, name: str) -> physics.Odometer:
        """Robot `name`'s encoders and mice, counting from where it stands now."""
        return physics.Odometer(self.physics.pose(name), self.sensor_errors, self.sensor_rng)

    def sense(self, name: str) -> dict:
        """Robot `name`'s readings now (and its odometry since the previous call)."""
        ph = self.physics
        mice, wheels = self.odometers[name].read(ph.pose(name))
        at = self.placed.pop(name, None)
        odo = odometry(mice=mice, wheels=wheels, placed=None if at is None else pose(*at))
        cam = up = None
        if self.view is not None:
            cam = camera(self.time, self._encode(self.frame(name)), pan=ph.robots[name].pan)
        if self.up is not None:
            up = {"image": self._encode(self.up_frame(name))}
        sonars = [sonar(b, r) for b, r in ph.sonars(name)]
        state, attack, kickoff, marker = self.referee.game(name)
        g = game(state, attack, None if kickoff is None else pose(*kickoff), marker)
        return sense(self.steps, self.time, g, odometry=odo, camera=cam, sonars=sonars,
                     up_camera=up)

    def _encode(self, img: np.ndarray) -> dict:
        if self.image == "rgb8":
            return rgb8_image(img.shape[1], img.shape[0], img)
        return jpeg_image(img, quality=90)

    def senses(self) -> dict[str, dict]:
        return {n: self.sense(n) for n in self.names}

    # ------------------------------------------------------------ acting and time

    def act(self, name: str, wheels=None, pan=None, kick: bool = False) -> None:
        """Applies one robot's command (wheel set-points rad/s, pan set-point rad, kick).
        The kicker fires only in play."""
        self.physics.command(name, wheels, pan)
        if kick and self.referee.state == "playing":
            _, _, heading = self.physics.pose(name)
            bx, by, _, _ = self.physics.ball()
            if self.physics.kick(name):
                self.referee.shot(name, (bx, by), heading)

    def advance(self) -> list[str]:
        """One step of physics, then the referee; returns the referee's calls."""
        ph = self.physics
        self.referee.account(ph.ball(), {n: ph.pose(n) for n in self.names})
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
            self.odometers[name] = self._odometer(name)
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
        if self.up is not None:
            self.up.renderer.close()


# --- play -------------------------------------------------------------------------------------


def play(args) -> dict:
    """Plays the match `args` (main's options) with the robots over zenoh; returns the summary."""
    m = Match(rf.find(args.scene, HERE), rf.find(args.camera, REPO), args.home, args.away,
              args.scenario, args.half, args.seed, args.image, placed=not args.no_placed,
              shadows=not args.no_shadows, samples=args.samples,
              up_camera=rf.find(args.up_camera, REPO) if args.up_camera else None,
              exact_odometry=args.exact_odometry)
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
        "stats": {team: {"shots": st.shots, "on_target": st.on_target,
                         "possession_steps": st.possession_steps}
                  for team, st in m.referee.stats.items()},
        "answered": answered,
        "missing": {n: world.steps - answered[n] for n in m.names},
        "render_ms": (round(1000 * float(np.mean(m.render_seconds)), 2)
                      if m.render_seconds else None),
        "up_render_ms": (round(1000 * float(np.mean(m.up_seconds)), 2)
                         if m.up_seconds else None),
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
        for which, suffix in (("camera", ""), ("up_camera", "_up")):
            image = (s.get(which) or {}).get("image")
            if not image:
                continue
            data = base64.b64decode(image["data"])
            if image["encoding"] == "jpeg":
                img = Image.open(io.BytesIO(data))
            else:
                img = Image.frombytes("RGB", (image["width"], image["height"]), data)
            img.save(out / f"{name}_{m.steps:05d}{suffix}.png")


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
    p.add_argument("--up-camera", metavar="FILE",
                   help="each robot's omnidirectional camera too (an omni camera file, e.g. "
                        "configs/vision/omni-ianus3.toml); default: none")
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
    p.add_argument("--exact-odometry", action="store_true",
                   help="mice and encoders without the errors of MRT's simulator (noise, "
                        "under-reading mice)")
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
