"""mrt_world.World and the stub world against a fake robot over zenoh on localhost."""

from __future__ import annotations

import json
import subprocess
import sys
import time
import unittest
from pathlib import Path

from fake_robot import FakeRobot, free_port
from test_protocol import schema_validator

from mrt_world import World, act_key, camera, game, odometry, rgb8_image, sense, sonar

PYTHON_DIR = Path(__file__).resolve().parents[1]


def readings(step: int, period: float = 0.1) -> dict:
    """A sense of every device at ``step``."""
    t = step * period
    return sense(
        step,
        t,
        game("playing", 1),
        odometry=odometry(mice=(0.0, 0.01, 0.0, 0.01), wheels=[0.2, 0.2]),
        camera=camera(t, rgb8_image(4, 3, bytes(36)), pan=0.0),
        sonars=[sonar(0.0, 3.0), sonar(3.14, None)],
    )


class Loopback(unittest.TestCase):
    """A World listening on a free port and fake robots connecting to it."""

    def setUp(self) -> None:
        self.endpoint = f"tcp/127.0.0.1:{free_port()}"
        self.world = World("test", ["r1"], listen=[self.endpoint])
        self.robots: list[FakeRobot] = []

    def tearDown(self) -> None:
        for robot in self.robots:
            robot.close()
        self.world.close()

    def robot(self, name: str = "r1", **kwargs) -> FakeRobot:
        robot = FakeRobot("test", name, self.endpoint, **kwargs)
        self.robots.append(robot)
        return robot

    def test_hundred_steps_end_and_bye(self) -> None:
        robot = self.robot()
        self.world.wait_for_robots(10.0)
        self.assertEqual(self.world.alive, {"r1"})
        for k in range(100):
            if k == 50:  # a stranger's act and garbage on the act key are dropped
                robot.session.put(act_key("test", "r1"), b"garbage")
                robot.session.put(
                    act_key("test", "r1"), json.dumps({**robot.acts[-1], "run": "other", "step": 50})
                )
            acts = self.world.step({"r1": readings(k)}, timeout=5.0)
            self.assertEqual(acts["r1"]["step"], k)
            self.assertEqual(acts["r1"]["wheels"], [10.0, 10.0])
            command = self.world.command("r1")
            self.assertFalse(command.stopped)
            self.assertEqual(command.kick, k % 10 == 9)
        self.assertEqual(robot.cycles, 100)
        self.assertEqual(self.world.steps, 100)
        self.assertEqual(self.world.dropped, {"malformed": 1, "stranger": 1})
        byes = self.world.end(timeout=5.0)
        self.assertEqual(byes["r1"]["steps"], 100)
        self.assertEqual(byes["r1"]["dropped"]["malformed"], 0)
        self.assertEqual(
            robot.end_message, {"protocol": 1, "world": "test", "run": self.world.run, "steps": 100}
        )
        self.assertEqual(robot.senses[7]["run"], self.world.run)
        self.assertRegex(self.world.run, r"^[0-9a-f]{8,16}$")

    def test_messages_follow_the_schemas(self) -> None:
        validators = {name: schema_validator(name) for name in ("sense", "act", "end", "bye")}
        robot = self.robot(answer=lambda step: {"wheels": None, "twist": None, "kick": False, "pan": None})
        self.world.wait_for_robots(10.0)
        for k in range(3):
            self.world.step({"r1": readings(k)})
        byes = self.world.end()
        for message in robot.senses:
            validators["sense"].validate(message)
        for message in robot.acts:
            validators["act"].validate(message)
        validators["end"].validate(robot.end_message)
        validators["bye"].validate(byes["r1"])

    def test_resend_after_a_lost_sense(self) -> None:
        robot = self.robot(lose={3})
        self.world.wait_for_robots(10.0)
        for k in range(6):
            started = time.monotonic()
            acts = self.world.step({"r1": readings(k)}, timeout=5.0, resend=0.2)
            self.assertEqual(acts["r1"]["step"], k)
            if k == 3:
                self.assertGreaterEqual(time.monotonic() - started, 0.2)
        self.assertEqual(robot.copies[3], 2)
        self.assertEqual(robot.cycles, 6)

    def test_repeat_is_answered_once_more(self) -> None:
        robot = self.robot()
        self.world.wait_for_robots(10.0)
        self.world.step({"r1": readings(0)})
        self.world.put_sense_bytes(
            "r1",
            json.dumps(
                {"protocol": 1, "world": "test", "run": self.world.run, "robot": "r1", **readings(0)}
            ).encode(),
        )
        self.world.step({"r1": readings(1)})
        self.world.drain(0.3)
        self.assertEqual(robot.cycles, 2)
        self.assertEqual(self.world.dropped, {"stale": 1})  # the repeat's answer came after step 0

    def test_timeout_and_safe_hold(self) -> None:
        def answer(step: int) -> dict | None:
            if 5 <= step <= 10:
                return None  # silent for 0.6 s of world time
            wheels = None if step == 1 else [1.0, 2.0] if step == 0 else [3.0, 4.0]
            twist = None if wheels is None else {"vx": float(step), "vy": 0.0, "omega": 0.0}
            return {"wheels": wheels, "twist": twist, "kick": False, "pan": None if step else 0.2}

        self.robot(answer=answer)
        first = self.world.command("r1")
        self.assertTrue(first.stopped)
        self.assertIsNone(first.wheels)
        self.world.wait_for_robots(10.0)
        commands = {}
        for k in range(12):
            acts = self.world.step({"r1": readings(k)}, timeout=0.15, resend=1.0)
            self.assertEqual(acts["r1"] is None, 5 <= k <= 10, k)
            commands[k] = self.world.command("r1")
        self.assertEqual(commands[0].wheels, [1.0, 2.0])
        self.assertEqual(commands[1].wheels, [1.0, 2.0])  # wheels None: the previous set-points
        self.assertEqual(commands[1].twist, {"vx": 0.0, "vy": 0.0, "omega": 0.0})
        self.assertEqual(commands[1].pan, 0.2)
        for k in range(2, 10):  # t = 0.9: 0.5 s after the last answer at t = 0.4, still held
            self.assertFalse(commands[k].stopped, k)
            self.assertEqual(commands[k].wheels, [3.0, 4.0], k)
        self.assertTrue(commands[10].stopped)  # t = 1.0: 0.6 s without an answer
        self.assertEqual(commands[10].wheels, [0.0, 0.0])
        self.assertEqual(commands[10].twist, {"vx": 0.0, "vy": 0.0, "omega": 0.0})
        self.assertFalse(commands[11].stopped)  # it answers again
        self.assertEqual(commands[11].wheels, [3.0, 4.0])

    def test_wait_for_robots_names_the_missing(self) -> None:
        endpoint = f"tcp/127.0.0.1:{free_port()}"
        with World("test2", ["here", "ghost"], listen=[endpoint]) as world:
            here = FakeRobot("test2", "here", endpoint)
            try:
                with self.assertRaisesRegex(TimeoutError, "ghost") as caught:
                    world.wait_for_robots(1.0)
                self.assertNotIn("here", str(caught.exception))
                self.assertEqual(world.alive, {"here"})
            finally:
                here.close()

    def test_step_checks_its_arguments(self) -> None:
        with self.assertRaises(ValueError):
            self.world.step({"r1": readings(1)})  # the first step is 0
        with self.assertRaises(ValueError):
            self.world.step({"r9": readings(0)})
        self.world.step({"r1": readings(0)}, timeout=0.01)  # nobody answers: None
        with self.assertRaises(ValueError):
            self.world.step({"r1": sense(1, 0.0, game("playing", 1))})  # time does not advance
        with self.assertRaises(ValueError):
            self.world.step({"r1": sense(1, 11.0, game("playing", 1))})  # a jump
        step = readings(1)
        del step["step"]  # the World numbers the steps
        self.assertIsNone(self.world.step({"r1": step}, timeout=0.01)["r1"])
        self.assertEqual(self.world.steps, 2)
        with self.assertRaises(ValueError):
            World("Bad Name", ["r1"])


class Stub(unittest.TestCase):
    """``python -m mrt_world.stub`` against fake robots."""

    def run_stub(
        self, robots: list[str], *options: str, **robot_options
    ) -> tuple[int, dict, list[FakeRobot]]:
        endpoint = f"tcp/127.0.0.1:{free_port()}"
        command = [
            sys.executable,
            "-m",
            "mrt_world.stub",
            "--world",
            "stub",
            "--listen",
            endpoint,
            "--timeout",
            "10",
        ]
        for robot in robots:
            command += ["--robot", robot]
        stub = subprocess.Popen(
            command + list(options), cwd=PYTHON_DIR, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        fakes = []
        try:
            time.sleep(0.3)  # a robot connects to a world that listens, else it waits for it
            fakes = [FakeRobot("stub", name, endpoint, **robot_options) for name in robots]
            out, err = stub.communicate(timeout=60)
        finally:
            stub.kill()
            for fake in fakes:
                fake.close()
        lines = out.splitlines()
        self.assertEqual(len(lines), 1, (out, err))
        return stub.returncode, json.loads(lines[0]), fakes

    def test_two_robots(self) -> None:
        code, summary, fakes = self.run_stub(["home-1", "home-2"], "--steps", "20", "--image", "jpeg")
        self.assertEqual(code, 0, summary)
        self.assertEqual(summary["answered"], {"home-1": 20, "home-2": 20})
        self.assertEqual(summary["missing"], {"home-1": 0, "home-2": 0})
        self.assertEqual(summary["byes"], {"home-1": True, "home-2": True})
        sense0, sense5 = fakes[0].senses[0], fakes[0].senses[5]
        mice = sense5["odometry"]["mice"]
        self.assertEqual((mice["x_left"], mice["x_right"]), (0.0, 0.0))  # straight ahead: no lateral motion
        self.assertAlmostEqual(mice["y_left"], 0.01)  # 0.1 m/s for 0.1 s
        self.assertAlmostEqual(mice["y_right"], 0.01)
        self.assertAlmostEqual(sense5["odometry"]["wheels"][0], 0.2)  # 0.01 m on wheels of radius 0.05 m
        self.assertEqual(sense0["odometry"]["wheels"], [0.0, 0.0])
        self.assertEqual(len(sense5["sonars"]), 16)
        self.assertEqual(sense5["camera"]["image"]["encoding"], "jpeg")
        self.assertAlmostEqual(sense5["time"], 0.5)

    def test_hostile(self) -> None:
        code, summary, fakes = self.run_stub(["home-1"], "--steps", "12", "--hostile", "--image", "rgb8")
        self.assertEqual(code, 0, summary)
        self.assertEqual(summary["missing"], {"home-1": 0})
        self.assertEqual(summary["answered_hostile"], {"home-1": 0})
        dropped = fakes[0].dropped
        for reason in ("malformed", "too_large", "protocol", "stranger", "out_of_order", "clock"):
            self.assertGreater(dropped[reason], 0, reason)
        self.assertEqual(dropped["too_large"], 1)

    def test_hostile_finds_a_naive_robot(self) -> None:
        code, summary, _ = self.run_stub(
            ["home-1"], "--steps", "5", "--hostile", "--image", "none", gate=False
        )
        self.assertEqual(code, 1)
        self.assertGreater(summary["answered_hostile"]["home-1"], 0)

    def test_no_robot(self) -> None:
        endpoint = f"tcp/127.0.0.1:{free_port()}"
        command = [
            sys.executable,
            "-m",
            "mrt_world.stub",
            "--robot",
            "home-1",
            "--steps",
            "5",
            "--listen",
            endpoint,
            "--timeout",
            "0.3",
        ]
        done = subprocess.run(command, cwd=PYTHON_DIR, capture_output=True, text=True, timeout=30)
        self.assertEqual(done.returncode, 1)
        summary = json.loads(done.stdout)
        self.assertEqual(
            (summary["steps"], summary["missing"], summary["byes"]), (0, {"home-1": 5}, {"home-1": False})
        )
        self.assertIn("home-1", done.stderr)


if __name__ == "__main__":
    unittest.main()
