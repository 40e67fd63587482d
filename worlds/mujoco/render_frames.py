#!/usr/bin/env python3
"""Renders what MRT's pinhole camera sees on the MuJoCo field, with the exact truth.

    python render_frames.py one --scene scenes/bright.xml --camera configs/vision/camera.toml \\
        --at -3,0,0 --ball -1.5,0.3 --robot 0,1,away --out frame.png
    python render_frames.py dataset --scene scenes/bright.xml --camera ... --count 60 \\
        --seed 1 --out frames/ [--empty 5] [--robots 2]

Frames: the field frame (metres; origin at the centre spot, +x towards the east goal, +y to the
north). A camera pose `x,y,heading` is the robot's: the camera's pan axis stands at
(mount_x_m, mount_y_m) in the robot frame (x ahead, y left), its optical centre height_m above
the floor, looking pan_deg to the left of the robot's heading and tilt_deg below the
horizontal. Pixels: columns to the right, rows downwards from the top-left corner; the centre
of pixel k is at k + 0.5, so a point at (u, v) lies in pixel (floor(u), floor(v)).

`dataset` writes DIR/frame_0000.png ... and DIR/truth.jsonl, one JSON object a frame:
  file, scene, camera_pose [x, y, heading_rad], ball [x, y] (field frame) or null,
  ball_robot [x, y] (the ball's floor point relative to the point under the camera, robot
  axes: x ahead, y left), distance (m, on the floor, from the point under the camera),
  bearing (rad, atan2(y, x) of ball_robot), pixel [col, row] (the ball centre projected),
  radius_px (ball radius * (fx + fy) / 2 / the distance from the optical centre to the ball
  centre), ball_pixels and ball_centroid [col, row] (the pixels that show the ball, from a
  segmentation render, and their centroid: off the image's centre a sphere images as an
  ellipse whose centre lies farther out than `pixel`), robots [[x, y, "home"|"away"], ...].
  Without a ball, every ball value is null (ball_pixels 0).

Needs MuJoCo with an OpenGL context: headless, set MUJOCO_GL=egl (or osmesa).
"""

import argparse
import json
import math
import os
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
PARKED_Z = -10.0  # where unused robots wait, under the carpet
HIDDEN_GROUP = 5  # parked robots' geoms are moved to this geom group, which is not drawn
BALL_AWAY = (0.0, 0.0, -5.0)  # the ball when a frame has none: under the carpet


def mujoco_module():
    """Imports MuJoCo, defaulting to EGL when no display is set."""
    if "MUJOCO_GL" not in os.environ and not os.environ.get("DISPLAY"):
        os.environ["MUJOCO_GL"] = "egl"
    import mujoco

    return mujoco


def find(path, base):
    """A path as given, or relative to `base` when it does not exist as given."""
    p = Path(path)
    if p.exists() or p.is_absolute():
        return p
    return base / p


# --- the camera ---------------------------------------------------------------------------


class Camera:
    """MRT's pinhole camera file (configs/vision/camera.toml) and its geometry."""

    def __init__(self, cfg):
        if cfg.get("model", "pinhole") != "pinhole":
            raise ValueError(f"only model = \"pinhole\" cameras can be rendered "
                             f"(got {cfg['model']!r})")
        self.width, self.height = int(cfg["width"]), int(cfg["height"])
        self.fx, self.fy = float(cfg["fx"]), float(cfg["fy"])
        self.cx, self.cy = float(cfg["cx"]), float(cfg["cy"])
        self.height_m = float(cfg["height_m"])
        self.tilt = math.radians(float(cfg["tilt_deg"]))
        self.pan = math.radians(float(cfg.get("pan_deg", 0.0)))
        self.mount = (float(cfg.get("mount_x_m", 0.0)), float(cfg.get("mount_y_m", 0.0)))
        if cfg.get("k1", 0.0) or cfg.get("k2", 0.0):
            print("warning: the renderer draws an ideal lens; k1 and k2 are ignored",
                  file=sys.stderr)

    @staticmethod
    def load(path):
        with open(path, "rb") as fh:
            return Camera(tomllib.load(fh))

    def centred(self):
        return self.fx == self.fy and self.cx == self.width / 2 and self.cy == self.height / 2

    def fovy_deg(self):
        return math.degrees(2.0 * math.atan((self.height / 2) / self.fy))

    def foot(self, pose):
        """The point under the optical centre (field frame)."""
        x, y, h = pose
        c, s = math.cos(h), math.sin(h)
        mx, my = self.mount
        return (x + c * mx - s * my, y + s * mx + c * my)

    def centre(self, pose):
        fx, fy = self.foot(pose)
        return np.array([fx, fy, self.height_m])

    def axes(self, pose):
        """The camera's right, down and forward axes in the field frame (rows of the matrix that
        takes field vectors to camera coordinates)."""
        yaw = pose[2] + self.pan
        ct, st = math.cos(self.tilt), math.sin(self.tilt)
        fwd = np.array([math.cos(yaw) * ct, math.sin(yaw) * ct, -st])
        right = np.array([math.sin(yaw), -math.cos(yaw), 0.0])
        down = np.cross(fwd, right)
        return np.array([right, down, fwd])

    def to_camera(self, pose, points):
        """Field points (N x 3) in camera coordinates: x right, y down, z along the axis."""
        return (np.atleast_2d(points) - self.centre(pose)) @ self.axes(pose).T

    def project(self, pose, points):
        """Pixels (N x 2: col, row) of field points, with their depths (N)."""
        c = self.to_camera(pose, points)
        z = c[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            uv = np.stack([self.cx + self.fx * c[:, 0] / z, self.cy + self.fy * c[:, 1] / z], 1)
        return uv, z

    def mujoco_quat(self, pose):
        """The orientation (w, x, y, z) of a MuJoCo camera frame (looking along -z, +y up)."""
        right, down, fwd = self.axes(pose)
        mat = np.stack([right, -down, -fwd], axis=1)  # columns: the camera frame's axes
        q = np.zeros(4)
        mujoco_module().mju_mat2Quat(q, mat.flatten())
        return q

    def horizontal_half_fov(self):
        return min(math.atan(self.cx / self.fx), math.atan((self.width - self.cx) / self.fx))


# --- the world ----------------------------------------------------------------------------


class World:
    """A scene file (scenes/*.xml, which includes field.xml), its model and a renderer."""

    def __init__(self, scene_path, camera, edit=None):
        """`edit`, when given, may change the scene's MjSpec before it is compiled (the tests
        add markers)."""
        mj = self.mj = mujoco_module()
        self.scene_path = Path(scene_path)
        self.name = self.scene_path.stem
        if edit is None:
            self.model = m = mj.MjModel.from_xml_path(str(self.scene_path))
        else:
            spec = mj.MjSpec.from_file(str(self.scene_path))
            edit(spec)
            self.model = m = spec.compile()
        self.data = mj.MjData(m)
        self.camera = camera
        self.cam_id = self._id(mj.mjtObj.mjOBJ_CAMERA, "eye")
        self.viewer = m.body_mocapid[self._id(mj.mjtObj.mjOBJ_BODY, "viewer")]
        self.ball_geom = self._id(mj.mjtObj.mjOBJ_GEOM, "ball")
        self.ball_radius = float(m.geom_size[self.ball_geom][0])
        joint = self._id(mj.mjtObj.mjOBJ_JOINT, "ball")
        self.ball_qpos = int(m.jnt_qposadr[joint])
        # Per team, each robot's mocap index and its geoms (with their groups).
        self.robots = {"home": [], "away": []}
        for team in self.robots:
            k = 0
            while (b := mj.mj_name2id(m, mj.mjtObj.mjOBJ_BODY, f"{team}{k}")) >= 0:
                geoms = range(m.body_geomadr[b], m.body_geomadr[b] + m.body_geomnum[b])
                self.robots[team].append((int(m.body_mocapid[b]),
                                          [(g, int(m.geom_group[g])) for g in geoms]))
                k += 1
        self.option = mj.MjvOption()
        self.option.geomgroup[HIDDEN_GROUP] = 0
        g = self._id(mj.mjtObj.mjOBJ_GEOM, "home0_0") if self.robots["home"] else -1
        self.robot_radius = float(m.geom_size[g][0]) if g >= 0 else 0.25
        carpet = self._id(mj.mjtObj.mjOBJ_GEOM, "carpet")
        self.half = (float(m.geom_size[carpet][0]), float(m.geom_size[carpet][1]))
        self.obstacles = self._obstacles()
        self._set_intrinsics()
        m.vis.global_.offwidth = max(m.vis.global_.offwidth, camera.width)
        m.vis.global_.offheight = max(m.vis.global_.offheight, camera.height)
        self.renderer = mj.Renderer(m, camera.height, camera.width)
        self.render_seconds = []

    def _id(self, kind, name):
        i = self.mj.mj_name2id(self.model, kind, name)
        if i < 0:
            raise ValueError(f"{self.scene_path}: no {kind.name[6:].lower()} named {name!r}")
        return i

    def _set_intrinsics(self):
        """The camera `eye` gets the file's intrinsics: a field of view when the principal point
        is the image centre and fx = fy; else MuJoCo's sensor model, for which the principal
        offset is (width/2 - cx, height/2 - cy) pixels (checked by tests/test_render.py)."""
        m, c, i = self.model, self.camera, self.cam_id
        m.cam_resolution[i] = (c.width, c.height)
        if c.centred():
            m.cam_fovy[i] = c.fovy_deg()
            m.cam_sensorsize[i] = (0.0, 0.0)
        else:
            s = 1e-3  # metres a pixel on the notional sensor
            m.cam_sensorsize[i] = (c.width * s, c.height * s)
            m.cam_intrinsic[i] = (c.fx * s, c.fy * s, (c.width / 2 - c.cx) * s,
                                  (c.height / 2 - c.cy) * s)

    def _obstacles(self):
        """Footprints of the fixed things a ball or robot cannot stand in: the goals' walls
        (boxes) and the posts (discs), from the model."""
        mj, m = self.mj, self.model
        boxes, discs = [], []
        for g in range(m.ngeom):
            name = mj.mj_id2name(m, mj.mjtObj.mjOBJ_GEOM, g) or ""
            pos, size = m.geom_pos[g], m.geom_size[g]
            if name.startswith("goal_") and pos[2] - size[2] < 0.3:
                boxes.append((pos[0] - size[0], pos[0] + size[0],
                              pos[1] - size[1], pos[1] + size[1]))
            elif name.startswith("post_"):
                discs.append((pos[0], pos[1], size[0]))
        return boxes, discs

    def clear_of(self, x, y, r):
        """Whether a disc of radius r at (x, y) is on the carpet and clear of goals and posts."""
        hx, hy = self.half
        if abs(x) > hx - r or abs(y) > hy - r:
            return False
        boxes, discs = self.obstacles
        for x0, x1, y0, y1 in boxes:
            dx, dy = max(x0 - x, 0, x - x1), max(y0 - y, 0, y - y1)
            if dx * dx + dy * dy < r * r:
                return False
        return all(math.hypot(x - px, y - py) >= r + pr for px, py, pr in discs)

    def place(self, pose, ball, robots):
        """Moves the camera, the ball ((x, y) on the floor, or None: away) and the robots
        ([(x, y, team)]; the others parked) and updates the kinematics."""
        m, d, c = self.model, self.data, self.camera
        d.mocap_pos[self.viewer] = c.centre(pose)
        d.mocap_quat[self.viewer] = c.mujoco_quat(pose)
        q = self.ball_qpos
        d.qpos[q:q + 3] = BALL_AWAY if ball is None else (ball[0], ball[1], self.ball_radius)
        d.qpos[q + 3:q + 7] = (1, 0, 0, 0)
        used = {"home": 0, "away": 0}
        for x, y, team in robots:
            slots = self.robots[team]
            if used[team] >= len(slots):
                raise ValueError(f"the scene has {len(slots)} {team} robots; "
                                 f"make_scene.py --robots N adds more")
            mocap, geoms = slots[used[team]]
            d.mocap_pos[mocap] = (x, y, 0.0)
            for g, group in geoms:
                m.geom_group[g] = group
            used[team] += 1
        # The others wait under the carpet, not drawn (nor in the shadow maps).
        for team, slots in self.robots.items():
            for k, (mocap, geoms) in enumerate(slots[used[team]:], used[team]):
                d.mocap_pos[mocap] = (2.0 * k, 0.0 if team == "home" else 2.0, PARKED_Z)
                for g, _ in geoms:
                    m.geom_group[g] = HIDDEN_GROUP
        self.mj.mj_forward(m, d)

    def render(self):
        t = time.perf_counter()
        self.renderer.update_scene(self.data, camera=self.cam_id, scene_option=self.option)
        img = self.renderer.render().copy()
        self.render_seconds.append(time.perf_counter() - t)
        return img

    def segment(self):
        """Per pixel, the geom shown (-1: none), from a segmentation render."""
        r, shadow = self.renderer, self.mj.mjtRndFlag.mjRND_SHADOW
        r.enable_segmentation_rendering()
        try:
            r.update_scene(self.data, camera=self.cam_id, scene_option=self.option)
            was, r.scene.flags[shadow] = r.scene.flags[shadow], 0
            seg = r.render()
            r.scene.flags[shadow] = was
        finally:
            r.disable_segmentation_rendering()
        geom = seg[:, :, 0].copy()
        geom[seg[:, :, 1] != self.mj.mjtObj.mjOBJ_GEOM] = -1
        return geom

    def seen(self, seg):
        """What the image shows of the ball: its pixel count and their centroid [col, row]
        (pixel centres at k + 0.5; null without ball pixels). Near the image's edges the
        centroid lies farther out than the projected centre: a sphere images as an ellipse."""
        rows, cols = np.nonzero(seg == self.ball_geom)
        centroid = None
        if len(rows):
            centroid = [round(float(cols.mean()) + 0.5, 3), round(float(rows.mean()) + 0.5, 3)]
        return {"ball_pixels": int(len(rows)), "ball_centroid": centroid}

    def ball_visible(self, pose, ball):
        """Whether the ball is wholly inside the image and nothing hides any of it: its outline
        projects inside the image with a pixel to spare, and rays from the optical centre to
        its centre and to 12 points near its outline hit the ball first."""
        c, r = self.camera, self.ball_radius
        centre = np.array([ball[0], ball[1], r])
        eye = c.centre(pose)
        view = centre - eye
        dist = np.linalg.norm(view)
        if dist <= r * 1.5:
            return False
        # The outline: where rays from the optical centre graze the sphere.
        w = view / dist
        a = np.cross(w, [0.0, 0.0, 1.0])
        a /= np.linalg.norm(a)
        b = np.cross(w, a)
        sin_g = r / dist
        cos_g = math.sqrt(1 - sin_g * sin_g)
        angles = np.linspace(0, 2 * math.pi, 36, endpoint=False)
        rim = [eye + dist * cos_g * (cos_g * w + sin_g * (math.cos(t) * a + math.sin(t) * b))
               for t in angles]
        uv, z = c.project(pose, np.array(rim))
        if np.any(z <= 0) or np.any(uv[:, 0] < 1) or np.any(uv[:, 0] > c.width - 1) \
                or np.any(uv[:, 1] < 1) or np.any(uv[:, 1] > c.height - 1):
            return False
        targets = [centre] + [centre + 0.9 * r * (math.cos(t) * a + math.sin(t) * b)
                              for t in angles[::3]]
        geom = np.zeros(1, dtype=np.int32)
        for p in targets:
            v = p - eye
            n = np.linalg.norm(v)
            self.mj.mj_ray(self.model, self.data, eye, v / n, None, 1, -1, geom)
            if geom[0] != self.ball_geom:
                return False
        return True

    def truth(self, pose, ball, robots):
        c = self.camera
        t = {"scene": self.name, "camera_pose": [round(v, 6) for v in pose],
             "ball": None, "ball_robot": None, "distance": None, "bearing": None,
             "pixel": None, "radius_px": None}
        if ball is not None:
            fx, fy = c.foot(pose)
            dx, dy = ball[0] - fx, ball[1] - fy
            h = pose[2]
            rx = math.cos(h) * dx + math.sin(h) * dy
            ry = -math.sin(h) * dx + math.cos(h) * dy
            centre = np.array([[ball[0], ball[1], self.ball_radius]])
            uv, _ = c.project(pose, centre)
            rng = float(np.linalg.norm(centre[0] - c.centre(pose)))
            t.update(ball=[round(ball[0], 6), round(ball[1], 6)],
                     ball_robot=[round(rx, 6), round(ry, 6)],
                     distance=round(math.hypot(rx, ry), 6), bearing=round(math.atan2(ry, rx), 6),
                     pixel=[round(float(uv[0, 0]), 3), round(float(uv[0, 1]), 3)],
                     radius_px=round(self.ball_radius * (c.fx + c.fy) / 2 / rng, 3))
        t["robots"] = [[round(x, 6), round(y, 6), team] for x, y, team in robots]
        return t


# --- sampling -----------------------------------------------------------------------------


def random_pose(world, rng):
    hx, hy = world.half
    m = world.robot_radius + 0.1
    while True:
        x, y = rng.uniform(-hx + m, hx - m), rng.uniform(-hy + m, hy - m)
        if world.clear_of(x, y, m):
            return (float(x), float(y), float(rng.uniform(-math.pi, math.pi)))


def random_robots(world, rng, pose, count, ball=None):
    """`count` robots on the field, most of them in front of the camera, clear of each other,
    of the camera's robot, of the ball, of the goals and the posts."""
    R, c = world.robot_radius, world.camera
    hx, hy = world.half
    out = []
    for _ in range(count):
        for _try in range(200):
            if rng.random() < 0.75:
                d = rng.uniform(0.8, 7.0)
                b = pose[2] + c.pan + rng.uniform(-1.2, 1.2) * c.horizontal_half_fov()
                x, y = pose[0] + d * math.cos(b), pose[1] + d * math.sin(b)
            else:
                x, y = rng.uniform(-hx + R, hx - R), rng.uniform(-hy + R, hy - R)
            x, y = float(x), float(y)
            ok = world.clear_of(x, y, R + 0.02)
            ok = ok and math.hypot(x - pose[0], y - pose[1]) > 2 * R + 0.1
            ok = ok and all(math.hypot(x - ox, y - oy) > 2 * R + 0.05 for ox, oy, _ in out)
            if ball is not None:
                ok = ok and math.hypot(x - ball[0], y - ball[1]) > R + world.ball_radius + 0.05
            if ok:
                out.append((x, y, "home" if rng.random() < 0.5 else "away"))
                break
    return out


def random_ball(world, rng, pose, robots, tries=60):
    """A ball 0.5 to 7 m (on the floor) from the point under the camera, wholly in view and
    hidden by nothing, clear of the robots; None after `tries` misses."""
    c, r, R = world.camera, world.ball_radius, world.robot_radius
    fx, fy = c.foot(pose)
    for _ in range(tries):
        d = rng.uniform(0.5, 7.0)
        b = pose[2] + c.pan + rng.uniform(-1, 1) * c.horizontal_half_fov()
        ball = (float(fx + d * math.cos(b)), float(fy + d * math.sin(b)))
        if not world.clear_of(ball[0], ball[1], r + 0.01):
            continue
        if any(math.hypot(ball[0] - x, ball[1] - y) < R + r + 0.05 for x, y, _ in robots):
            continue
        world.place(pose, ball, robots)
        if world.ball_visible(pose, ball):
            return ball
    return None


# --- the commands -------------------------------------------------------------------------


def save_png(img, path):
    from PIL import Image

    Image.fromarray(img).save(path, optimize=True)


def floats(text, n, what):
    parts = text.split(",")
    if len(parts) != n:
        raise SystemExit(f"{what}: expected {n} comma-separated numbers, got {text!r}")
    return [float(p) for p in parts]


def cmd_one(args):
    camera = Camera.load(find(args.camera, REPO))
    world = World(find(args.scene, HERE), camera)
    x, y, hdeg = floats(args.at, 3, "--at")
    pose = (x, y, math.radians(hdeg))
    ball = tuple(floats(args.ball, 2, "--ball")) if args.ball else None
    robots = []
    for spec in args.robot or []:
        parts = spec.split(",")
        if len(parts) != 3 or parts[2] not in ("home", "away"):
            raise SystemExit(f"--robot: expected x,y,home|away, got {spec!r}")
        robots.append((float(parts[0]), float(parts[1]), parts[2]))
    world.place(pose, ball, robots)
    img = world.render()
    save_png(img, args.out)
    t = world.truth(pose, ball, robots)
    t["file"] = str(args.out)
    t.update(world.seen(world.segment()))
    if ball is not None and not world.ball_visible(pose, ball):
        print("note: the ball is not wholly in view", file=sys.stderr)
    print(json.dumps(t))


def make_dataset(scene, camera_path, count, seed, out, empty=0, robots=0, quiet=False):
    """Renders `count` frames with a ball and `empty` without; returns the truth records."""
    camera = Camera.load(camera_path)
    world = World(scene, camera)
    rng = np.random.default_rng(seed)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    records = []
    total = count + empty
    started = time.perf_counter()
    for k in range(total):
        with_ball = k < count
        while True:
            pose = random_pose(world, rng)
            if with_ball:
                others = random_robots(world, rng, pose, robots)
                ball = random_ball(world, rng, pose, others)
                if ball is not None:
                    break
            else:
                ball, others = None, random_robots(world, rng, pose, robots)
                break
        world.place(pose, ball, others)
        img = world.render()
        name = f"frame_{k:04d}.png"
        save_png(img, out / name)
        rec = {"file": name, **world.truth(pose, ball, others), **world.seen(world.segment())}
        if ball is None and rec["ball_pixels"]:
            raise RuntimeError(f"{name}: the ball was to be out of view")
        records.append(rec)
        if not quiet and ((k + 1) % 10 == 0 or k + 1 == total):
            print(f"{world.name}: {k + 1}/{total} frames", flush=True)
    with open(out / "truth.jsonl", "w") as fh:
        for rec in records:
            fh.write(json.dumps(rec) + "\n")
    if not quiet:
        ms = 1000 * float(np.mean(world.render_seconds))
        wall = time.perf_counter() - started
        print(f"{world.name}: {total} frames in {out}; rendering {ms:.1f} ms a frame "
              f"(mean), {1000 * wall / total:.0f} ms a frame with sampling, checks and PNG")
    world.renderer.close()
    return records


def cmd_dataset(args):
    make_dataset(find(args.scene, HERE), find(args.camera, REPO), args.count, args.seed,
                 args.out, args.empty, args.robots)


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    # `--at -3,0,0`: a value that starts with a minus sign is a value, not an option.
    for k in range(len(argv) - 1):
        if argv[k] in ("--at", "--ball", "--robot") and argv[k + 1].startswith("-"):
            argv[k], argv[k + 1] = f"{argv[k]}={argv[k + 1]}", None
    argv = [a for a in argv if a is not None]

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n".join(__doc__.splitlines()[1:]))
    sub = ap.add_subparsers(dest="command", required=True)
    for name in ("one", "dataset"):
        p = sub.add_parser(name)
        p.add_argument("--scene", required=True,
                       help="a scene file (relative paths also tried from worlds/mujoco/)")
        p.add_argument("--camera", default="configs/vision/camera.toml",
                       help="a camera TOML file (relative paths also tried from the repository "
                            "root; default %(default)s)")
        p.add_argument("--out", required=True,
                       help="the PNG (one) or the directory (dataset)")
    one = sub.choices["one"]
    one.add_argument("--at", required=True, help="the robot's pose x,y,heading_deg (field frame)")
    one.add_argument("--ball", help="the ball's floor point x,y (omit: no ball)")
    one.add_argument("--robot", action="append", help="a robot x,y,home|away (repeatable)")
    ds = sub.choices["dataset"]
    ds.add_argument("--count", type=int, required=True, help="frames with a ball")
    ds.add_argument("--seed", type=int, required=True)
    ds.add_argument("--empty", type=int, default=0, help="extra frames without a ball")
    ds.add_argument("--robots", type=int, default=0, help="random robots a frame")
    args = ap.parse_args(argv)
    {"one": cmd_one, "dataset": cmd_dataset}[args.command](args)


if __name__ == "__main__":
    main()
