"""Tests of the playable world: physics.py (bodies, encoders, mice, kicker, ball, sonars),
referee.py and world.py over zenoh with a fake robot.

    MUJOCO_GL=egl python -m unittest discover -s worlds/mujoco/tests

The physics tests need MuJoCo, the loopback test MuJoCo with an OpenGL context (EGL or OSMesa
headless) and zenoh; each skips, saying why, without them. The kinematics and referee tests
need nothing.
"""

import json
import math
import socket
import sys
import tempfile
import threading
import unittest
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent
REPO = HERE.parent.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(REPO / "python"))

import physics as ph  # noqa: E402
import referee as rr  # noqa: E402

SCENE = HERE / "scenes" / "bright.xml"
CAMERA_FILE = REPO / "configs" / "vision" / "camera.toml"

try:
    import render_frames as rf

    rf.mujoco_module()  # MUJOCO_GL=egl unless set or on a desktop, before MuJoCo is imported
    _NO_MUJOCO = None
except ImportError as e:
    _NO_MUJOCO = (f"MuJoCo is not installed here ({e}): "
                  "pip install -r worlds/mujoco/requirements.txt")


def needs_mujoco(test):
    test.setUp = lambda self: _NO_MUJOCO and self.skipTest(_NO_MUJOCO)
    return test


def rendering_unavailable():
    """None when MuJoCo renders offscreen here and zenoh is installed, else why not."""
    if _NO_MUJOCO:
        return _NO_MUJOCO
    try:
        import zenoh  # noqa: F401
    except ImportError as e:
        return f"zenoh is not installed here ({e}): pip install -r python/requirements.txt"
    try:
        import render_frames as rf

        mj = rf.mujoco_module()
        m = mj.MjModel.from_xml_string("<mujoco><worldbody><geom size='1' type='sphere'/>"
                                       "</worldbody></mujoco>")
        r = mj.Renderer(m, 8, 8)
        r.update_scene(mj.MjData(m))
        r.render()
        r.close()
    except Exception as e:  # no EGL/OSMesa, no GPU driver ...
        return (f"MuJoCo cannot render offscreen here ({e}); headless, set MUJOCO_GL=egl "
                "or osmesa")
    return None


# --- what the robot does with the readings (crates/mrt-robot/src/base.rs, mrt-perception's
# mice.rs), written out independently of physics.py ---------------------------------------------


def arc(vx, vy, dtheta):
    """The displacement (robot frame at the start) of a constant body velocity along an arc."""
    k = 1.0 if abs(dtheta) < 1e-12 else math.sin(dtheta / 2) / (dtheta / 2)
    s, c = math.sin(dtheta / 2), math.cos(dtheta / 2)
    return k * (c * vx - s * vy), k * (s * vx + c * vy), dtheta


def from_encoders(turns):
    """Base::motion for IANUS3: wheel turns -> the displacement."""
    left, right = turns
    return arc(0.05 * (left + right) / 2, 0.0, 0.05 * (right - left) / 0.40)


def from_mice(m, distance=0.2):
    """The two mice's readings -> the displacement, when they fit the model (x̄_l = x̄_r)."""
    x_left, y_left, x_right, y_right = m
    assert abs(x_left - x_right) < 1e-9, m
    return arc((y_left + y_right) / 2, -x_left, (y_right - y_left) / distance)


def compose(p, d):
    x, y, t = p
    dx, dy, dt = d
    return x + math.cos(t) * dx - math.sin(t) * dy, y + math.sin(t) * dx + math.cos(t) * dy, t + dt


class KinematicsTest(unittest.TestCase):
    def test_readings_of_an_arc_invert_to_it(self):
        for d in [(0.1, 0.0, 0.0), (0.08, 0.004, 0.1), (0.0, 0.0, -0.5), (-0.05, 0.01, 0.3)]:
            mice = ph.mice_readings(*d)
            self.assertAlmostEqual(mice[0], mice[2])
            # the encoders see the arc's forward motion and turn (not the sideways slip)
            vx, _ = ph.arc_velocity(*d)
            for got, want in zip(from_encoders(ph.wheel_turns(*d)), arc(vx, 0.0, d[2])):
                self.assertAlmostEqual(got, want)
            for got, want in zip(from_mice(mice), d):
                self.assertAlmostEqual(got, want)

    def test_the_mice_signs(self):
        # Forward: both ȳ positive; a turn to the left: the right mouse goes farther; a slip to
        # the left: x̄ negative (x̄ is to the robot's right).
        self.assertGreater(ph.mice_readings(0.1, 0, 0)[1], 0)
        xl, yl, xr, yr = ph.mice_readings(0.0, 0.0, 0.2)
        self.assertAlmostEqual(yr, 0.02)
        self.assertAlmostEqual(yl, -0.02)
        self.assertLess(ph.mice_readings(0.0, 0.05, 0.0)[0], 0)
        left, right = ph.wheel_turns(0.0, 0.0, 0.2)
        self.assertLess(left, 0)
        self.assertGreater(right, 0)

    def test_the_ramp_keeps_the_curvature(self):
        w = ph.ramp([0.0, 0.0], [10.0, 20.0], 0.1)  # 6 rad/s at most
        self.assertAlmostEqual(w[1], 6.0)
        self.assertAlmostEqual(w[0], 3.0)
        self.assertEqual(ph.ramp([0.0, 0.0], [100.0, 50.0], 10.0), [24.0, 12.0])


# --- the physics --------------------------------------------------------------------------------


@needs_mujoco
class SensorErrorsTest(unittest.TestCase):
    """The mice and encoders err as MRT's simulator's do (configs/sim/default.toml)."""

    def readings(self, errors, seed=7, n=4000):
        import numpy as np

        odo = ph.Odometer((0.0, 0.0, 0.0), errors, np.random.default_rng(seed))
        out, x = [], 0.0
        for _ in range(n):  # 0.1 m straight ahead each reading
            x += 0.1
            out.append(odo.read((x, 0.0, 0.0)))
        return out

    def test_without_errors_the_readings_are_exact(self):
        exact = list(ph.mice_readings(0.1, 0.0, 0.0)) + ph.wheel_turns(0.1, 0.0, 0.0)
        for mice, turns in self.readings(None, n=10):
            for got, want in zip(list(mice) + turns, exact):
                self.assertAlmostEqual(got, want, delta=1e-12)

    def test_the_mice_under_read_and_scatter_and_the_wheels_scatter(self):
        e = ph.SensorErrors()
        got = self.readings(e)
        ys = [m[1] for m, _ in got] + [m[3] for m, _ in got]
        xs = [m[0] for m, _ in got] + [m[2] for m, _ in got]
        mean = sum(ys) / len(ys)
        # Under-reading 2 % of the time by 25 % on average: 0.5 % short on the mean.
        self.assertAlmostEqual(mean, 0.1 * (1 - e.mice_miss * 0.25), delta=0.0002)
        spread = math.sqrt(sum(v * v for v in xs) / len(xs))
        self.assertAlmostEqual(spread, e.mice_noise * 0.1, delta=0.0001)
        self.assertTrue(all(m[1] > 0.045 for m, _ in got))  # never below half, less noise
        turn = ph.wheel_turns(0.1, 0.0, 0.0)[0]
        ws = [t[0] / turn - 1.0 for _, t in got]
        self.assertAlmostEqual(math.sqrt(sum(v * v for v in ws) / len(ws)), e.wheel_noise,
                               delta=0.003)
        # The same seed, the same errors.
        self.assertEqual(got[:50], self.readings(e)[:50])
        self.assertNotEqual(got[:50], self.readings(e, seed=8)[:50])


class PhysicsTest(unittest.TestCase):
    def physics(self, home=1, away=0):
        model, data = ph.compile_scene(SCENE, home, away)
        p = ph.Physics(model, data, home, away)
        p.place_ball(-8.5, -5.5)  # out of the way (the scene has it on the centre spot)
        return p

    def drive(self, p, name, wheels, seconds):
        """Drives `name` at `wheels` for `seconds`; returns the pose the robot would track from
        its encoders and from its mice, and the readings of each step."""
        start = p.pose(name)
        odo = ph.Odometer(start)
        by_wheels, by_mice, steps = start, start, []
        p.command(name, wheels)
        for _ in range(round(seconds / 0.1)):
            p.step(0.1)
            mice, turns = odo.read(p.pose(name))
            by_wheels = compose(by_wheels, from_encoders(turns))
            by_mice = compose(by_mice, from_mice(mice))
            steps.append((mice, turns))
        return by_wheels, by_mice, steps

    def test_straight_ahead(self):
        p = self.physics()
        p.place_robot("home-1", (-5.0, 1.0, 0.3))
        by_wheels, by_mice, steps = self.drive(p, "home-1", [20.0, 20.0], 2.0)
        # 1 m/s after a ramp of 20 / 60 s: 2 - 1/6 m along the heading, less the servo's lag.
        x, y, t = p.pose("home-1")
        moved = math.hypot(x + 5.0, y - 1.0)
        self.assertAlmostEqual(moved, 2.0 - 1.0 / 6.0 - ph.SERVO_TIME, delta=0.005)
        self.assertAlmostEqual(math.atan2(y - 1.0, x + 5.0), 0.3, delta=1e-3)
        self.assertAlmostEqual(t, 0.3, delta=1e-3)
        self.assertAlmostEqual(sum(s[1][0] for s in steps), moved / 0.05, delta=1e-6)
        for est in (by_wheels, by_mice):
            self.assertLess(math.hypot(est[0] - x, est[1] - y), 1e-6)
            self.assertAlmostEqual(est[2], t, delta=1e-6)
        mice, turns = steps[-1]
        self.assertAlmostEqual(mice[1], 0.1, delta=1e-3)  # ȳ: 0.1 m a step at 1 m/s
        self.assertAlmostEqual(turns[0], 2.0, delta=0.01)  # 20 rad/s for 0.1 s

    def test_turning_in_place_and_on_an_arc(self):
        p = self.physics()
        p.place_robot("home-1", (0.0, 0.0, 0.0))
        by_wheels, by_mice, steps = self.drive(p, "home-1", [-6.0, 6.0], 2.0)
        # 1.5 rad/s after a ramp of 0.1 s, less the servo's lag
        x, y, t = p.pose("home-1")
        self.assertAlmostEqual(t, 1.5 * (2.0 - 0.05 - ph.SERVO_TIME), delta=0.005)
        self.assertLess(math.hypot(x, y), 0.01)
        mice, turns = steps[-1]
        self.assertAlmostEqual(turns[0], -0.6, delta=0.01)
        self.assertAlmostEqual(turns[1], 0.6, delta=0.01)
        self.assertAlmostEqual((mice[3] - mice[1]) / 0.2, 0.15, delta=1e-3)
        # An arc: 10 and 14 rad/s, v = 0.6 m/s, ω = 0.5 rad/s (radius 1.2 m).
        p.place_robot("home-1", (0.0, 0.0, 0.0))
        by_wheels, by_mice, steps = self.drive(p, "home-1", [10.0, 14.0], 3.0)
        x, y, t = p.pose("home-1")
        expect, w, body = (0.0, 0.0, 0.0), [0.0, 0.0], [0.0, 0.0]
        for _ in range(3000):  # the ramp, the servo's lag and the kinematics, in 1 ms steps
            w = ph.ramp(w, [10.0, 14.0], 0.001)
            body = [b + (c - b) * 0.001 / ph.SERVO_TIME for b, c in zip(body, ph.wheels_twist(*w))]
            expect = compose(expect, arc(body[0] * 0.001, 0.0, body[1] * 0.001))
        self.assertLess(math.hypot(x - expect[0], y - expect[1]), 0.01)
        self.assertAlmostEqual(t, expect[2], delta=0.01)
        # On the arc the wheels slip sideways a little (the centripetal force): 3.6 mm/s,
        # which the mice see and the encoders cannot.
        self.assertLess(math.hypot(by_mice[0] - x, by_mice[1] - y), 1e-3)
        self.assertLess(math.hypot(by_wheels[0] - x, by_wheels[1] - y), 0.015)
        for est in (by_wheels, by_mice):
            self.assertAlmostEqual(est[2], t, delta=1e-4)

    def test_a_robot_driven_into_a_wall_stops_and_its_encoders_say_so(self):
        p = self.physics()
        p.place_robot("home-1", (8.5, 3.0, 0.0))  # the east wall's face at x = 10
        by_wheels, by_mice, steps = self.drive(p, "home-1", [24.0, 24.0], 4.0)
        x, y, t = p.pose("home-1")
        self.assertAlmostEqual(x, 10.0 - 0.25, delta=0.01)
        self.assertAlmostEqual(y, 3.0, delta=0.01)
        for mice, turns in steps[-20:]:  # the last 2 s: pushing, not moving
            self.assertLess(max(abs(v) for v in turns), 0.01)
            self.assertLess(max(abs(v) for v in mice), 0.001)
        self.assertLess(math.hypot(by_wheels[0] - x, by_wheels[1] - y), 0.01)
        # stalled, not spinning on: it backs off at once (0.5 m/s after a ramp of 0.2 s)
        self.drive(p, "home-1", [-10.0, -10.0], 1.0)
        self.assertAlmostEqual(p.pose("home-1")[0], 9.75 - 0.5 * (1.0 - 0.1 - 0.02), delta=0.05)

    def test_the_ball_rolls_slows_and_stops(self):
        p = self.physics()
        p.place_robot("home-1", (0.0, -5.0, 0.0))
        p.place_ball(-8.0, 2.0, 2.0, 0.0)
        p.step(1.0)
        # viscous, 0.4 1/s: 2 e^-0.4 after 1 s
        self.assertAlmostEqual(p.ball()[2], 2.0 * math.exp(-0.4), delta=0.05)
        for _ in range(150):
            p.step(0.1)
        x, y, vx, vy = p.ball()
        self.assertLess(math.hypot(vx, vy), 0.005, "the ball still rolls after 16 s")
        # at most v / 0.4 = 5 m; the dry friction that stops it takes a little off
        self.assertTrue(4.0 < x + 8.0 <= 5.0, x + 8.0)
        self.assertAlmostEqual(y, 2.0, delta=0.01)

    def test_a_kick_reaches_only_a_near_ball_and_needs_a_charge(self):
        p = self.physics()
        p.place_robot("home-1", (0.0, 0.0, 0.5))
        c, s = math.cos(0.5), math.sin(0.5)

        def ball_at(gap, bearing=0.0):
            d = 0.25 + 0.11 + gap
            p.place_ball(d * math.cos(0.5 + bearing), d * math.sin(0.5 + bearing))

        p.time = 10.0
        ball_at(0.05)
        self.assertTrue(p.kick("home-1"))
        _, _, vx, vy = p.ball()
        self.assertAlmostEqual(vx, 6.0 * c, delta=1e-6)
        self.assertAlmostEqual(vy, 6.0 * s, delta=1e-6)
        p.step(0.1)
        self.assertAlmostEqual(math.hypot(*p.ball()[2:]), 6.0 * math.exp(-0.04), delta=0.1)
        ball_at(0.05)
        p.time = 10.5
        self.assertFalse(p.kick("home-1"), "recharging")
        self.assertEqual(p.ball()[2:], (0.0, 0.0))
        p.time = 12.0
        ball_at(0.2)
        self.assertFalse(p.kick("home-1"), "out of reach")
        p.time = 14.0
        ball_at(0.05, 0.5)
        self.assertFalse(p.kick("home-1"), "beside the kicker")
        p.time = 16.0
        ball_at(0.1, -0.3)
        self.assertTrue(p.kick("home-1"))
        self.assertAlmostEqual(math.hypot(*p.ball()[2:]), 6.0, delta=1e-6)

    def test_sonar_ranges_to_the_walls(self):
        p = self.physics(home=2)
        p.place_robot("home-1", (8.0, 4.5, 0.0))
        p.place_robot("home-2", (-3.0, 0.0, math.pi))
        p.place_ball(-8.0, -5.0)
        ring = p.sonars("home-1")
        self.assertEqual(len(ring), 16)
        self.assertAlmostEqual(ring[1][0], 2 * math.pi / 16)
        self.assertAlmostEqual(ring[0][1], 10.0 - 8.0, delta=0.03)  # east wall
        self.assertAlmostEqual(ring[4][1], 7.0 - 4.5, delta=0.03)  # north wall
        self.assertIsNone(ring[8][1])  # 17 m of field behind it
        # home-2 faces west: home-1 is not seen (11 m), home-2's bearing 0 is the west goal
        ring = p.sonars("home-2")
        self.assertIsNone(ring[0][1])
        p.place_robot("home-1", (-4.5, 0.0, 0.0))  # 1.5 m ahead of home-2, edge at 1.25
        self.assertAlmostEqual(p.sonars("home-2")[0][1], 1.25, delta=0.03)
        self.assertAlmostEqual(p.sonars("home-1")[0][1], 1.25, delta=0.03)


# --- the referee --------------------------------------------------------------------------------


class RefereeTest(unittest.TestCase):
    NAMES = ["home-1", "home-2", "away-1", "away-2"]

    def poses(self, **at):
        p = {"home-1": (-8.0, 0, 0), "home-2": (-3.0, 2.0, 0), "away-1": (8.0, 0, 0),
             "away-2": (3.0, -2.0, 0)}
        p.update({k.replace("_", "-"): v for k, v in at.items()})
        return p

    def test_initial_ready_set_playing(self):
        r = rr.Referee(self.NAMES, half=100)
        self.assertEqual(r.game("home-1"), ("initial", 1, None, "magenta"))
        self.assertEqual(r.game("away-2")[1:], (-1, None, "cyan"))
        d = r.update(1.0, 1.0, (0, 0), self.poses())
        self.assertEqual((r.state, d.ball), ("ready", (0.0, 0.0)))
        state, attack, kickoff, _ = r.game("home-1")
        self.assertEqual(kickoff, (-8.5, 0.0, 0.0))  # the keeper on its goal line
        self.assertAlmostEqual(r.game("home-2")[2][0], -0.61)  # home kicks off
        self.assertGreaterEqual(math.hypot(*r.game("away-2")[2][:2]), 2.25)  # outside the circle
        self.assertEqual(r.game("away-1")[2], (8.5, 0.0, math.pi))
        # everyone there but away-2: ready waits, then away-2 is placed
        there = {n: r.formation[n] for n in self.NAMES}
        there["away-2"] = (0.0, -5.0, 0.0)
        self.assertEqual(r.update(5.0, 0.1, (0, 0), there).robots, {})
        self.assertEqual(r.state, "ready")
        d = r.update(11.0, 0.1, (0.3, 0), there)
        self.assertEqual(r.state, "set")
        self.assertEqual(d.robots, {"away-2": r.formation["away-2"]})
        self.assertEqual(d.ball, (0.0, 0.0))
        # a robot on the centre spot at the kickoff: the ball waits beside it, the robot is
        # put at its place when READY ends
        r2 = rr.Referee(self.NAMES, half=100)
        d2 = r2.update(1.0, 1.0, (0, 0), self.poses(home_2=(0.1, 0.0, 0.0)))
        self.assertGreater(abs(d2.ball[1]), 0.36)
        d2 = r2.update(11.0, 10.0, (0, 0), {**r2.formation, "home-2": (-0.35, 0.0, 0.0)})
        self.assertEqual(list(d2.robots), ["home-2"])
        self.assertEqual(d2.ball, (0.0, 0.0))
        r.update(11.5, 0.1, (0, 0), there)
        self.assertEqual(r.state, "set")
        r.update(12.0, 0.1, (0, 0), there)
        self.assertEqual((r.state, r.play_time), ("playing", 0.0))
        r.update(12.1, 0.1, (0, 0), there)
        self.assertAlmostEqual(r.play_time, 0.1)

    def playing(self, **kw):
        return rr.Referee(self.NAMES, start="playing", **kw)

    def test_a_goal_counts_and_leads_to_ready(self):
        r = self.playing(half=100)
        r.update(0.1, 0.1, (9.05, 0.2), self.poses())  # not wholly over the line
        self.assertEqual((r.state, r.score["home"]), ("playing", 0))
        d = r.update(0.2, 0.1, (9.2, 0.5), self.poses())
        self.assertEqual(r.score, {"home": 1, "away": 0})
        self.assertEqual(r.goals[0]["team"], "home")
        self.assertEqual((r.state, d.ball, r.kicking), ("ready", (0.0, 0.0), "away"))
        self.assertAlmostEqual(r.game("away-2")[2][0], 0.61)  # away kicks off, from the east
        # an own goal: the ball in home's own (west) goal is away's
        r = self.playing(half=100)
        r.update(0.1, 0.1, (-9.3, -0.8), self.poses())
        self.assertEqual((r.score, r.kicking), ({"home": 0, "away": 1}, "home"))
        # beside the goal: out, not a goal
        r = self.playing(half=100)
        d = r.update(0.1, 0.1, (9.3, 1.2), self.poses())
        self.assertEqual((r.score["home"], r.state), (0, "playing"))
        self.assertEqual(d.ball, (8.5, 1.2))

    def test_a_ball_out_is_put_back_inside(self):
        r = self.playing(half=100)
        self.assertEqual(r.update(0.1, 0.1, (3.0, 6.2), self.poses()).ball, (3.0, 5.5))
        self.assertEqual(r.update(0.2, 0.1, (-2.0, -6.4), self.poses()).ball, (-2.0, -5.5))
        self.assertEqual(r.update(0.3, 0.1, (-9.5, 4.0), self.poses()).ball, (-8.5, 4.0))
        self.assertEqual(r.update(0.4, 0.1, (9.4, -6.5), self.poses()).ball, (8.5, -5.5))
        # a robot on the spot: the ball goes beside it, along the line
        x, y = r.update(0.5, 0.1, (3.0, 6.2), self.poses(home_2=(3.0, 5.5, 0))).ball
        self.assertEqual(y, 5.5)
        self.assertGreater(abs(x - 3.0), 0.36)
        self.assertIsNone(r.update(0.6, 0.1, (3.0, 5.9), self.poses()).ball)  # on the line: in
        self.assertEqual(r.state, "playing")

    def test_halves_swap_the_attack_then_the_match_ends(self):
        r = self.playing(half=1.0)
        self.assertEqual((r.attack("home"), r.attack("away")), (1, -1))
        for k in range(10):
            r.update(0.1 * (k + 1), 0.1, (0, 0), self.poses())
        self.assertEqual((r.half, r.state, r.kicking), (2, "ready", "away"))
        self.assertEqual((r.attack("home"), r.attack("away")), (-1, 1))
        self.assertEqual(r.game("home-1")[2], (8.5, 0.0, math.pi))  # home's keeper, east now
        r.state = "playing"
        for k in range(10):
            r.update(2 + 0.1 * k, 0.1, (0, 0), self.poses())
        self.assertEqual(r.state, "finished")
        self.assertAlmostEqual(r.play_time, 2.0)

    def test_empty_goal_ends_at_the_first_goal(self):
        r = rr.Referee(["home-1"], half=60, halves=1, start="playing", until_goal=True)
        r.update(0.1, 0.1, (-9.5, 0.0), {"home-1": (0, 0, 0)})
        self.assertEqual((r.state, r.score), ("finished", {"home": 0, "away": 1}))

    def test_a_shot_is_on_target_when_its_line_crosses_the_mouth_it_attacks(self):
        # By hand: the east goal line at x = 9 m, the mouth 1 - 0.11 = 0.89 m either side.
        # From (5, 0) at 10 degrees the ball crosses at 4 tan 10 = 0.705 m: in; at 15, 1.07 m.
        self.assertTrue(rr.heads_into_goal((5.0, 0.0), math.radians(10), 9.0, 0.89))
        self.assertFalse(rr.heads_into_goal((5.0, 0.0), math.radians(15), 9.0, 0.89))
        self.assertFalse(rr.heads_into_goal((5.0, 0.0), math.pi, 9.0, 0.89))
        self.assertFalse(rr.heads_into_goal((5.0, 0.0), math.pi / 2, 9.0, 0.89))
        r = self.playing(half=100)
        r.shot("home-2", (5.0, 0.0), math.radians(10))  # home attacks east: on target
        r.shot("home-2", (5.0, 0.0), math.radians(15))
        r.shot("away-1", (5.0, 0.0), 0.0)  # away attacks west: not at its goal
        r.shot("away-1", (-5.0, 0.3), math.pi)
        self.assertEqual((r.stats["home"].shots, r.stats["home"].on_target), (2, 1))
        self.assertEqual((r.stats["away"].shots, r.stats["away"].on_target), (2, 1))
        r.half = 2  # the halves swap the goals
        r.shot("home-1", (-5.0, 0.3), math.pi)
        self.assertEqual(r.stats["home"].on_target, 2)

    def test_possession_goes_to_the_closest_robot_within_a_metre(self):
        r = self.playing(half=100)
        r.account((-2.5, 2.0), self.poses())  # home-2 at 0.5 m
        r.account((3.2, -2.0), self.poses(home_2=(3.0, -1.5, 0)))  # away-2 closer, 0.2 m
        r.account((0.0, 4.0), self.poses())  # nobody within 1 m
        self.assertEqual([r.stats[t].possession_steps for t in ("home", "away")], [1, 1])


@needs_mujoco
class MatchTest(unittest.TestCase):
    """world.Match without the network and without images: the referee on the physics."""

    def match(self, **kw):
        import world

        return world.Match(SCENE, CAMERA_FILE, render=False, **kw)

    def test_a_ball_rolled_into_the_goal_is_a_goal_and_the_ball_goes_back(self):
        m = self.match(home=1, away=1, scenario="match", half=100)
        m.referee.state = "playing"
        m.physics.place_ball(7.0, 0.3, 3.0, 0.0)
        calls = []
        for _ in range(20):
            calls += m.advance()
        self.assertEqual(m.referee.score, {"home": 1, "away": 0}, calls)
        self.assertEqual(m.referee.state, "ready")
        self.assertIn("goal home (1:0)", calls)
        self.assertLess(math.hypot(*m.physics.ball()[:2]), 0.02)

    def test_a_ball_out_is_re_placed_and_play_goes_on(self):
        m = self.match(home=1, away=0, scenario="match", half=100)
        m.referee.state = "playing"
        m.physics.place_robot("home-1", (-5.0, -5.0, 0.0))
        m.physics.place_ball(2.0, 5.0, 0.0, 3.0)  # towards the north wall
        for _ in range(10):
            calls = m.advance()
            if calls:
                break
        self.assertTrue(calls and calls[0].startswith("out"), calls)
        x, y, vx, vy = m.physics.ball()
        self.assertAlmostEqual(y, 5.5, delta=1e-6)
        self.assertAlmostEqual(x, 2.0, delta=0.05)
        self.assertEqual((vx, vy), (0.0, 0.0))
        self.assertEqual(m.referee.state, "playing")

    def test_a_kick_that_reaches_the_ball_counts_as_a_shot_only_in_play(self):
        m = self.match(home=1, away=0, scenario="match", half=100)
        m.physics.place_robot("home-1", (5.0, 0.0, 0.0))
        m.physics.place_ball(5.0 + 0.25 + 0.11 + 0.05, 0.0)
        m.physics.time = 10.0
        m.act("home-1", kick=True)  # before play: the kicker does not fire
        self.assertEqual((m.referee.stats["home"].shots, m.physics.ball()[2]), (0, 0.0))
        m.referee.state = "playing"
        m.act("home-1", kick=True)
        self.assertEqual((m.referee.stats["home"].shots, m.referee.stats["home"].on_target),
                         (1, 1))
        m.advance()
        self.assertEqual(m.referee.stats["home"].possession_steps, 1)
        m.physics.time = 20.0
        m.act("home-1", kick=True)  # the ball is gone: no shot
        self.assertEqual(m.referee.stats["home"].shots, 1)

    def test_the_empty_goal_start_comes_from_the_seed(self):
        a, b, c = (self.match(home=1, away=0, scenario="empty-goal", seed=s) for s in (3, 3, 4))
        self.assertEqual(a.physics.pose("home-1"), b.physics.pose("home-1"))
        self.assertNotEqual(a.physics.pose("home-1"), c.physics.pose("home-1"))
        for m in (a, c):
            x, y, _ = m.physics.pose("home-1")
            bx, by, _, _ = m.physics.ball()
            self.assertGreaterEqual(math.hypot(bx - x, by - y), 1.0)
            self.assertLess(abs(x), 9.0)
            self.assertLess(abs(by), 6.0)
            self.assertEqual(m.referee.state, "playing")
            s = m.sense("home-1")
            self.assertEqual(s["odometry"]["placed"]["x"], x)  # put down by hand: told where
            self.assertIsNone(m.sense("home-1")["odometry"]["placed"])


class UpCameraTest(unittest.TestCase):
    """The omnidirectional camera images the floor as its file's affine map says, a raised
    point pushed out by viewpoint / (viewpoint - z), and nothing beyond the mirror's reach."""

    def setUp(self):
        why = rendering_unavailable()
        if why:
            self.skipTest(why)

    def test_the_ball_is_where_the_omni_model_puts_it_all_round_the_robot(self):
        import tomllib

        import world

        path = REPO / "configs" / "vision" / "omni-ianus3.toml"
        cfg = tomllib.loads(path.read_text())
        m = world.Match(SCENE, CAMERA_FILE, 1, 0, "empty-goal", seed=1, up_camera=path)
        x, y, t = 1.0, -2.0, 0.7
        m.physics.place_robot("home-1", (x, y, t))
        vp, scale, r = cfg["viewpoint_m"], cfg["scale_px_per_m"], m.physics.ball_radius
        for dx, dy in ((0.45, 0.0), (0.0, 1.2), (-2.0, -1.5), (3.0, 1.0)):
            bx = x + math.cos(t) * dx - math.sin(t) * dy
            by = y + math.sin(t) * dx + math.cos(t) * dy
            m.physics.place_ball(bx, by)
            img = m.up_frame("home-1").astype(int)
            self.assertEqual(img.shape, (cfg["height"], cfg["width"], 3))
            ball = (img[..., 0] > 120) & (img[..., 1] < 110) & (img[..., 2] < 80)
            rows, cols = ball.nonzero()
            self.assertGreater(len(rows), 10, (dx, dy))
            k = vp / (vp - r)  # the ball's centre, raised by its radius
            col = cfg["cx"] - scale * dy * k
            row = cfg["cy"] - scale * dx * k
            self.assertAlmostEqual(cols.mean() + 0.5, col, delta=1.5, msg=(dx, dy))
            self.assertAlmostEqual(rows.mean() + 0.5, row, delta=1.5, msg=(dx, dy))
        # Beyond the reach, black; the image goes to the robot with each sense.
        self.assertEqual(int(img[0, 0].sum()), 0)
        self.assertGreater(int(img[cfg["height"] // 2, cfg["width"] // 2 + 40].sum()), 0)
        up = m.sense("home-1")["up_camera"]["image"]
        self.assertEqual((up["width"], up["height"], up["encoding"]), (320, 320, "jpeg"))
        m.close()


# --- over zenoh -----------------------------------------------------------------------------


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class FakeRobot:
    """A robot that answers each sense with the same wheel speeds and pan, and says bye at the
    end (the robot's side of docs/devices.md, without its checks)."""

    def __init__(self, world, name, endpoint, wheels=(10.0, 10.0), pan=0.3):
        import zenoh

        from mrt_world import act_key, alive_key, bye_key, end_key, sense_key

        self.world, self.name, self.wheels, self.pan = world, name, list(wheels), pan
        self.senses, self.ended = [], threading.Event()
        self.run = None
        self._act, self._bye = act_key(world, name), bye_key(world, name)
        config = zenoh.Config()
        config.insert_json5("mode", '"peer"')
        config.insert_json5("scouting/multicast/enabled", "false")
        config.insert_json5("connect/endpoints", json.dumps([endpoint]))
        self.session = zenoh.open(config)
        self.session.declare_subscriber(sense_key(world, name), self._on_sense)
        self.session.declare_subscriber(end_key(world), self._on_end)
        self.token = self.session.liveliness().declare_token(alive_key(world, name))

    def _on_sense(self, sample):
        m = json.loads(sample.payload.to_bytes())
        if self.senses and m["step"] == self.senses[-1]["step"]:
            return  # a resend: the answer is on its way
        self.run = m["run"]
        self.senses.append(m)
        act = {"protocol": 1, "world": self.world, "run": m["run"], "robot": self.name,
               "step": m["step"], "wheels": self.wheels, "twist": None, "kick": False,
               "pan": self.pan, "faults": []}
        self.session.put(self._act, json.dumps(act).encode())

    def _on_end(self, sample):
        m = json.loads(sample.payload.to_bytes())
        bye = {"protocol": 1, "world": self.world, "run": m["run"], "robot": self.name,
               "steps": len(self.senses), "faults": [],
               "dropped": dict.fromkeys(("malformed", "too_large", "protocol", "stranger",
                                         "out_of_order", "clock"), 0)}
        self.session.put(self._bye, json.dumps(bye).encode())
        self.ended.set()

    def close(self):
        self.session.close()


class LoopbackTest(unittest.TestCase):
    def setUp(self):
        why = rendering_unavailable()
        if why:
            self.skipTest(why)

    def test_thirty_steps_with_a_fake_robot_end_with_a_bye(self):
        import base64
        import io

        from PIL import Image

        import world

        endpoint = f"tcp/127.0.0.1:{free_port()}"
        with tempfile.TemporaryDirectory() as tmp:
            truth = Path(tmp, "truth.jsonl")
            args = world.parser().parse_args([
                "play", "--scene", "scenes/bright.xml", "--camera", str(CAMERA_FILE),
                "--listen", endpoint, "--world", "loopback", "--scenario", "empty-goal",
                "--seed", "2", "--steps", "30", "--truth", str(truth), "--no-shadows",
                "--wait", "20"])
            result = {}
            thread = threading.Thread(target=lambda: result.update(world.play(args)))
            thread.start()
            robot = FakeRobot("loopback", "home-1", endpoint)
            try:
                thread.join(120)
                self.assertFalse(thread.is_alive(), "the world did not end")
            finally:
                robot.close()
            lines = [json.loads(line) for line in truth.read_text().splitlines()]
        self.assertEqual(result["steps"], 30)
        self.assertEqual(result["answered"], {"home-1": 30})
        self.assertEqual(result["missing"], {"home-1": 0})
        self.assertEqual(result["byes"], {"home-1": True})
        self.assertEqual((result["world"], result["scenario"], result["seed"]),
                         ("loopback", "empty-goal", 2))
        self.assertGreater(result["render_ms"], 0)
        self.assertTrue(robot.ended.is_set())
        # What the robot got: images of its camera's size, its pan, its odometry.
        self.assertEqual([s["step"] for s in robot.senses], list(range(30)))
        first, last = robot.senses[0], robot.senses[-1]
        self.assertIsNotNone(first["odometry"]["placed"])
        image = last["camera"]["image"]
        self.assertEqual((image["width"], image["height"], image["encoding"]), (320, 240, "jpeg"))
        self.assertEqual(Image.open(io.BytesIO(base64.b64decode(image["data"]))).size, (320, 240))
        self.assertAlmostEqual(last["camera"]["pan"], 0.3)  # reached at 3 rad/s
        self.assertEqual(last["game"]["state"], "playing")
        self.assertEqual(len(last["sonars"]), 16)
        # 10 rad/s a wheel: 0.5 m/s straight ahead (unless the ball was in the way)
        self.assertAlmostEqual(last["odometry"]["wheels"][0], 1.0, delta=0.05)
        self.assertEqual(len(lines), 30)
        x0, y0, _ = lines[0]["robots"]["home-1"]
        x1, y1, _ = lines[-1]["robots"]["home-1"]
        turned = sum(s["odometry"]["wheels"][0] for s in robot.senses[1:]) * 0.05
        self.assertAlmostEqual(math.hypot(x1 - x0, y1 - y0), turned, delta=0.06)
        self.assertAlmostEqual(math.hypot(x1 - x0, y1 - y0), 0.5 * 2.9 - 0.5 * 10 / 60 * 0.5,
                               delta=0.1)


if __name__ == "__main__":
    unittest.main()
