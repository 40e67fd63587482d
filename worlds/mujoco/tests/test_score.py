"""Tests of score_frames.py: detections scored against a dataset's truth, worked by hand.

    python -m unittest discover -s worlds/mujoco/tests

Needs numpy, not MuJoCo.
"""

import math
import sys
import unittest
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

try:
    import numpy  # noqa: F401
except ImportError as e:
    raise unittest.SkipTest(f"numpy is not installed here ({e})")

import render_frames as rf  # noqa: E402
import score_frames as sf  # noqa: E402

CAMERA = rf.Camera.load(HERE.parent.parent.parent / "configs" / "vision" / "camera.toml")


def frame(name, ball=None, robots=(), pose=(0.0, 0.0, 0.0)):
    """A truth record: the camera's robot at `pose`, a ball `ball` (distance, bearing rad) or
    none, robots [(x, y, team)]."""
    t = {"file": name, "camera_pose": list(pose), "robots": [list(r) for r in robots],
         "distance": None, "bearing": None}
    if ball is not None:
        t["distance"], t["bearing"] = ball
    return t


class ScoreTest(unittest.TestCase):
    def test_the_ball_and_the_robots_are_scored_against_the_truth(self):
        truths = [
            # A ball 2 m ahead; a robot 3 m ahead (its nearest point at 2.75 m), one behind.
            frame("a.png", ball=(2.0, 0.0), robots=[(3.0, 0.0, "away"), (-3.0, 0.0, "home")]),
            # No ball; a home robot 4 m away at 10 degrees to the left.
            frame("b.png", robots=[(4.0 * math.cos(0.1745), 4.0 * math.sin(0.1745), "home")]),
        ]
        detections = {
            "a.png": [
                {"class": "ball", "distance_m": 2.1, "bearing_deg": 1.0},
                {"class": "robot", "distance_m": 2.75 * 1.02, "bearing_deg": 0.5,
                 "marker": "cyan"},
                {"class": "robot", "distance_m": 5.0, "bearing_deg": 25.0, "marker": None},
                {"class": "robot", "distance_m": 1.5, "bearing_deg": -1.0, "marker": None},
            ],
            "b.png": [
                {"class": "ball", "distance_m": 3.0, "bearing_deg": 0.0},
                {"class": "robot", "distance_m": 3.75, "bearing_deg": 11.0, "marker": "cyan"},
            ],
        }
        s = sf.score(CAMERA, truths, detections)
        ball = s["ball"]
        self.assertEqual((ball["frames_with_ball"], ball["found"]), (1, 1))
        self.assertAlmostEqual(ball["range_error_pct"]["mean"], 5.0, places=3)
        self.assertAlmostEqual(ball["bearing_error_deg"]["worst"], 1.0, places=3)
        self.assertEqual((ball["empty_frames"], ball["balls_in_empty_frames"]), (1, 1))
        robots = s["robots"]
        self.assertEqual((robots["in_view"], robots["found"]), (2, 2))
        # 5 m at 25 degrees: nobody there; 1.5 m dead ahead: where the away robot stands,
        # but at half its distance.
        self.assertEqual((robots["misplaced"], robots["phantoms"]), (1, 1))
        self.assertAlmostEqual(robots["distance_error_pct"]["median"], 2.0, places=2)
        self.assertAlmostEqual(robots["bearing_error_deg"]["worst"], 1.0, delta=0.01)
        self.assertEqual(robots["markers"], {"right": 1, "wrong": 1, "none": 0})

    def test_a_robot_too_far_or_cut_by_the_image_is_not_in_view(self):
        t = frame("c.png", robots=[(9.0, 0.0, "away"), (0.5, 0.0, "away"), (3.0, 3.0, "home")])
        seen = sf.robots_seen_from(CAMERA, t)
        # 8.75 m: beyond the range; 0.25 m: below the image; 45 degrees: beside it.
        self.assertEqual([r["in_view"] for r in seen], [False, False, False])
        # Found anyway by its bearing (its foot cut off), it is neither scored nor a phantom.
        s = sf.score(CAMERA, [t], {"c.png": [{"class": "robot", "distance_m": 0.8,
                                              "bearing_deg": 0.0, "marker": None}]})
        self.assertEqual((s["robots"]["found"], s["robots"]["phantoms"]), (0, 0))

    def test_a_net_is_scored_when_its_goal_is_wholly_in_view(self):
        # 5 m from the east goal line, facing it: both posts' feet in view, the net 5 m ahead.
        # Facing west from the same spot, the east goal is behind, the west one 13 m ahead.
        ahead = frame("d.png", pose=(4.0, 0.0, 0.0))
        behind = frame("e.png", pose=(4.0, 0.0, math.pi))
        nets = sf.nets_seen_from(CAMERA, ahead)
        self.assertTrue(nets["east"]["in_view"])
        self.assertFalse(nets["west"]["in_view"])
        self.assertAlmostEqual(nets["east"]["distance"], 5.0)
        self.assertFalse(sf.nets_seen_from(CAMERA, behind)["east"]["in_view"])
        self.assertTrue(sf.nets_seen_from(CAMERA, behind)["west"]["in_view"])
        s = sf.score(CAMERA, [ahead, behind], {
            "d.png": [{"class": "net", "goal": "east", "distance_m": 5.1, "bearing_deg": -0.5}],
            "e.png": [{"class": "net", "goal": "east", "distance_m": 5.0, "bearing_deg": 0.0}],
        })
        n = s["nets"]
        # The west net, in view in e.png, was not reported; the east one there is behind.
        self.assertEqual((n["in_view"], n["found"], n["not_wholly_in_view"]), (2, 1, 1))
        self.assertAlmostEqual(n["distance_error_pct"]["mean"], 2.0, places=3)
        self.assertAlmostEqual(n["bearing_error_deg"]["mean"], 0.5, places=3)

    def test_a_spread_is_of_its_errors(self):
        self.assertIsNone(sf.spread([]))
        s = sf.spread([float(k) for k in range(1, 11)])
        self.assertEqual((s["count"], s["mean"], s["median"], s["worst"]), (10, 5.5, 6.0, 10.0))


if __name__ == "__main__":
    unittest.main()
