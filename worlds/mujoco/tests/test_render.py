"""Tests of the MuJoCo field and render_frames.py.

    MUJOCO_GL=egl python -m unittest discover -s worlds/mujoco/tests

They need MuJoCo with an OpenGL context (EGL or OSMesa headless) and skip without one.
"""

import json
import math
import sys
import tempfile
import unittest
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent
REPO = HERE.parent.parent
sys.path.insert(0, str(HERE))

try:
    import numpy as np

    import render_frames as rf
    _MISSING = None
except ImportError as e:  # pip install -r worlds/mujoco/requirements.txt
    _MISSING = f"MuJoCo rendering is not available here: {e} (see worlds/mujoco/README.md)"

SCENES = ["bright", "half", "warm", "side"]
CAMERA_FILE = REPO / "configs" / "vision" / "camera.toml"

# A camera with everything the file format allows off its defaults: fx != fy, the principal
# point off the centre (and off the pixel grid), a panned head mounted off the robot's
# centre, another image size.
ODD_CAMERA = {
    "model": "pinhole", "width": 400, "height": 300, "fx": 300.0, "fy": 330.0,
    "cx": 185.5, "cy": 161.25, "height_m": 0.6, "tilt_deg": 25.0, "pan_deg": 30.0,
    "mount_x_m": 0.12, "mount_y_m": -0.05,
}

_AVAILABLE = None


def rendering_available():
    """None when MuJoCo can render offscreen here, else why not."""
    global _AVAILABLE
    if _MISSING:
        return _MISSING
    if _AVAILABLE is None:
        try:
            mj = rf.mujoco_module()
            m = mj.MjModel.from_xml_string("<mujoco><worldbody><geom size='1' type='sphere'/>"
                                           "</worldbody></mujoco>")
            r = mj.Renderer(m, 8, 8)
            r.update_scene(mj.MjData(m))
            r.render()
            r.close()
            _AVAILABLE = ""
        except Exception as e:  # no module, no EGL/OSMesa, no GPU driver ...
            _AVAILABLE = (f"MuJoCo offscreen rendering is not available here ({e}); "
                          "headless, set MUJOCO_GL=egl or osmesa")
    return _AVAILABLE or None


def rust_project(cfg, pose, p):
    """The pixel of field point p for the camera file `cfg` at robot pose `pose`, written out
    as crates/mrt-perception/src/camera.rs does it (independently of render_frames.Camera):
    camera axes (right, down, forward) = Rz(pan) * [[0, -s, c], [-1, 0, 0], [0, -c, -s]]
    with (s, c) = sin/cos(tilt), in the robot frame; robot frame = Rz(heading) of the field."""
    x, y, h = pose
    s, c = math.sin(math.radians(cfg["tilt_deg"])), math.cos(math.radians(cfg["tilt_deg"]))
    axes = np.array([[0.0, -s, c], [-1.0, 0.0, 0.0], [0.0, -c, -s]])
    pan = math.radians(cfg.get("pan_deg", 0.0))
    rz = lambda a: np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0],
                             [0, 0, 1]])
    cam_to_robot = rz(pan) @ axes
    mount = np.array([cfg.get("mount_x_m", 0.0), cfg.get("mount_y_m", 0.0), cfg["height_m"]])
    robot = rz(-h) @ (np.asarray(p, float) - np.array([x, y, 0.0]))
    v = cam_to_robot.T @ (robot - mount)
    uv = np.array([cfg["cx"] + cfg["fx"] * v[0] / v[2], cfg["cy"] + cfg["fy"] * v[1] / v[2]])
    return uv, v[2]


def add_marker(spec):
    mj = rf.mujoco_module()
    body = spec.worldbody.add_body(name="marker", mocap=True, pos=[0, 0, -3])
    body.add_geom(name="marker", type=mj.mjtGeom.mjGEOM_SPHERE, size=[0.03, 0, 0],
                  rgba=[1, 0, 0, 1], contype=0, conaffinity=0)


class ProjectionTest(unittest.TestCase):
    """Points projected with the pinhole formula land where MuJoCo draws them."""

    def setUp(self):
        why = rendering_available()
        if why:
            self.skipTest(why)

    def check_camera(self, cfg, poses, name):
        camera = rf.Camera(cfg)
        world = rf.World(HERE / "scenes" / "bright.xml", camera, edit=add_marker)
        mj = world.mj
        marker = world.model.body_mocapid[mj.mj_name2id(world.model, mj.mjtObj.mjOBJ_BODY,
                                                         "marker")]
        geom = mj.mj_name2id(world.model, mj.mjtObj.mjOBJ_GEOM, "marker")
        rng = np.random.default_rng(7)
        errors = []
        for pose in poses:
            world.place(pose, None, [])
            centre, axes = camera.centre(pose), camera.axes(pose)
            done = 0
            while done < 8:
                # A point seen at a random pixel, 1.5 to 4 m along the optical axis.
                u = rng.uniform(15, camera.width - 15)
                v = rng.uniform(15, camera.height - 15)
                z = rng.uniform(1.5, 4.0)
                cam = np.array([(u - camera.cx) / camera.fx * z,
                                (v - camera.cy) / camera.fy * z, z])
                p = centre + axes.T @ cam
                if p[2] < 0.08:
                    continue  # under the carpet
                expect, depth = rust_project(cfg, pose, p)
                self.assertGreater(depth, 0)
                self.assertLess(np.abs(expect - (u, v)).max(), 1e-9, "the formulas disagree")
                world.data.mocap_pos[marker] = p
                mj.mj_forward(world.model, world.data)
                rows, cols = np.nonzero(world.segment() == geom)
                self.assertGreater(len(rows), 3, f"{name}: no marker at {p}")
                seen = np.array([cols.mean() + 0.5, rows.mean() + 0.5])
                errors.append(np.abs(seen - expect).max())
                done += 1
        world.renderer.close()
        worst = max(errors)
        print(f"\n{name}: {len(errors)} markers, worst error {worst:.3f} px, "
              f"mean {np.mean(errors):.3f} px", file=sys.stderr)
        self.assertLess(worst, 1.0)

    def test_the_project_camera_file(self):
        import tomllib

        cfg = tomllib.loads(CAMERA_FILE.read_text())
        self.check_camera(cfg, [(0.0, 0.0, 0.0), (-2.0, 1.0, 2.5), (3.0, -2.0, -1.0)],
                          "camera.toml")

    def test_a_camera_with_every_parameter_off_its_default(self):
        self.check_camera(ODD_CAMERA, [(0.0, 0.0, 0.3), (-1.0, 2.0, -2.0), (2.0, -1.0, 3.0)],
                          "odd camera")

    def test_the_conventions(self):
        """Rows grow downwards, columns to the right, pan to the left (no rendering)."""
        import tomllib

        cfg = tomllib.loads(CAMERA_FILE.read_text())
        cam = rf.Camera(cfg)
        pose = (0.0, 0.0, 0.0)
        u, v = cam.project(pose, [[3.0, 0.0, cam.height_m]])[0][0]
        self.assertAlmostEqual(u, cfg["cx"])
        self.assertLess(v, cfg["cy"])  # level with the camera: above the centre (tilted down)
        left = cam.project(pose, [[3.0, 1.0, 0.0]])[0][0]
        self.assertLess(left[0], cfg["cx"])  # +y (left) appears left
        below = cam.project(pose, [[2.0, 0.0, 0.0]])[0][0]
        self.assertGreater(below[1], v)  # the floor nearer: lower in the image
        panned = rf.Camera({**cfg, "pan_deg": 30.0})
        ahead = [[3 * math.cos(math.radians(30)), 3 * math.sin(math.radians(30)), 0.2]]
        self.assertAlmostEqual(panned.project(pose, ahead)[0][0][0], cfg["cx"])
        for p in ([1.0, 0.5, 0.1], [4.0, -2.0, 0.0]):
            ours, theirs = cam.project(pose, [p])[0][0], rust_project(cfg, pose, p)[0]
            self.assertLess(np.abs(ours - theirs).max(), 1e-9)


class SceneTest(unittest.TestCase):
    def setUp(self):
        why = rendering_available()
        if why:
            self.skipTest(why)

    def test_every_scene_loads_and_is_lit_by_its_lights_or_the_headlamp_alone(self):
        mj = rf.mujoco_module()
        names = sorted(p.stem for p in (HERE / "scenes").glob("*.xml"))
        self.assertTrue(set(SCENES) <= set(names), names)
        for name in names:
            m = mj.MjModel.from_xml_path(str(HERE / "scenes" / f"{name}.xml"))
            if name == "headlamp":
                self.assertEqual((m.nlight, m.vis.headlight.active), (0, 1), name)
            else:
                self.assertGreater(m.nlight, 0, name)
                self.assertEqual(m.vis.headlight.active, 0, name)
            for obj, what in ((mj.mjtObj.mjOBJ_BODY, "ball"), (mj.mjtObj.mjOBJ_BODY, "viewer"),
                              (mj.mjtObj.mjOBJ_CAMERA, "eye"), (mj.mjtObj.mjOBJ_BODY, "home0"),
                              (mj.mjtObj.mjOBJ_BODY, "away0")):
                self.assertGreaterEqual(mj.mj_name2id(m, obj, what), 0, f"{name}: {what}")
        mj.MjModel.from_xml_path(str(HERE / "field.xml"))

    def test_a_dataset_comes_again_from_its_seed(self):
        from PIL import Image

        with tempfile.TemporaryDirectory() as a, tempfile.TemporaryDirectory() as b:
            for out in (a, b):
                rf.make_dataset(HERE / "scenes" / "bright.xml", CAMERA_FILE, 2, 11, out,
                                empty=1, robots=2, quiet=True)
            ta = Path(a, "truth.jsonl").read_text()
            self.assertEqual(ta, Path(b, "truth.jsonl").read_text())
            recs = [json.loads(line) for line in ta.splitlines()]
            self.assertEqual(len(recs), 3)
            self.assertIsNone(recs[2]["ball"])
            for rec in recs:
                pa = np.asarray(Image.open(Path(a, rec["file"])))
                pb = np.asarray(Image.open(Path(b, rec["file"])))
                self.assertTrue(np.array_equal(pa, pb), rec["file"])

    def test_the_truth_pixel_is_orange_in_a_bright_frame(self):
        from PIL import Image

        with tempfile.TemporaryDirectory() as out:
            recs = rf.make_dataset(HERE / "scenes" / "bright.xml", CAMERA_FILE, 3, 5, out,
                                   robots=2, quiet=True)
            for rec in recs:
                img = np.asarray(Image.open(Path(out, rec["file"]))).astype(float) / 255
                u, v = rec["pixel"]
                r, g, b = img[int(v), int(u)]
                hue = 60 * (g - b) / (r - min(g, b))  # red is the largest: orange's hue
                self.assertTrue(r >= g >= b and 5 <= hue <= 45 and (r - b) / r > 0.6,
                                f"{rec['file']}: {img[int(v), int(u)] * 255} at {u}, {v}")
                self.assertGreater(rec["ball_pixels"], 0.5 * math.pi * rec["radius_px"] ** 2)
                self.assertTrue(0.5 <= rec["distance"] <= 7.0)
                self.assertAlmostEqual(rec["bearing"],
                                       math.atan2(rec["ball_robot"][1], rec["ball_robot"][0]),
                                       places=5)


if __name__ == "__main__":
    unittest.main()
