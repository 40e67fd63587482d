"""Keys, builders and parsers of mrt_world.protocol."""

from __future__ import annotations

import base64
import io
import json
import unittest
from pathlib import Path

import numpy as np
from PIL import Image

from mrt_world import (
    ProtocolError,
    act_key,
    alive_key,
    bye_key,
    camera,
    encode,
    end_key,
    game,
    jpeg_image,
    odometry,
    parse_act,
    parse_bye,
    pose,
    rgb8_image,
    seen,
    sense,
    sense_key,
    sonar,
)

SCHEMAS = Path(__file__).resolve().parents[2] / "schemas" / "devices" / "1"


def schema_validator(name: str):
    """A jsonschema validator for ``schemas/devices/1/<name>.schema.json``, or SkipTest."""
    path = SCHEMAS / f"{name}.schema.json"
    if not path.exists():
        raise unittest.SkipTest(f"{path} does not exist yet (the Rust side generates it)")
    try:
        import jsonschema
    except ImportError:
        raise unittest.SkipTest("jsonschema is not installed") from None
    schema = json.loads(path.read_text())
    return jsonschema.Draft202012Validator(schema)


def act(**changes) -> bytes:
    """A good act of robot r1 in world w, run abc, step 7, with ``changes``."""
    message = {
        "protocol": 1,
        "world": "w",
        "run": "abc",
        "robot": "r1",
        "step": 7,
        "wheels": [1.0, -2],
        "twist": {"vx": 0.1, "vy": 0.0, "omega": 0.2},
        "kick": False,
        "pan": 0.3,
        "faults": [],
    }
    message.update(changes)
    return json.dumps({k: v for k, v in message.items() if v is not ...}).encode()


def full_sense(robot: str = "r1") -> dict:
    """A sense with every device, as the World sends it."""
    image = rgb8_image(2, 1, bytes(range(6)))
    s = sense(
        3,
        0.3,
        game("ready", -1, kickoff_pose=pose(-1.0, 0.5, 0.0), marker="cyan"),
        odometry=odometry(mice=(0.0, 0.01, 0.0, 0.01), wheels=[0.2, 0.2], placed=pose(0, 0, 3.14)),
        camera=camera(0.3, image, pan=0.1),
        up_camera=image,
        sonars=[sonar(0.0, 2.0), sonar(0.39, None)],
    )
    return {"protocol": 1, "world": "w", "run": "abc", "robot": robot, **s}


class Keys(unittest.TestCase):
    def test_keys(self) -> None:
        self.assertEqual(sense_key("stub", "home-1"), "mrt/devices/1/stub/home-1/sense")
        self.assertEqual(act_key("stub", "home-1"), "mrt/devices/1/stub/home-1/act")
        self.assertEqual(bye_key("stub", "home_2"), "mrt/devices/1/stub/home_2/bye")
        self.assertEqual(alive_key("a", "b"), "mrt/devices/1/a/b/alive")
        self.assertEqual(end_key("stub"), "mrt/devices/1/stub/end")

    def test_bad_names(self) -> None:
        for name in ("", "Home", "a/b", "a*", "é", "x" * 65, "a b", None):
            with self.subTest(name=name), self.assertRaises(ValueError):
                sense_key("stub", name)  # type: ignore[arg-type]
        with self.assertRaises(ValueError):
            end_key("**")
        self.assertTrue(sense_key("x" * 64, "0-_"))


class Builders(unittest.TestCase):
    def test_sense(self) -> None:
        s = sense(0, 0.0, game("playing", 1))
        self.assertEqual(s["step"], 0)
        self.assertNotIn("world", s)
        self.assertIsNone(s["camera"])
        self.assertEqual(s["game"], {"state": "playing", "attack": 1, "kickoff_pose": None, "marker": None})
        with self.assertRaises(ValueError):
            sense(-1, 0.0, game("playing", 1))
        with self.assertRaises(ValueError):
            sense(0, float("nan"), game("playing", 1))
        up = full_sense()["up_camera"]
        self.assertEqual(set(up), {"image"})

    def test_game_odometry_sonar(self) -> None:
        for bad in (lambda: game("kickoff", 1), lambda: game("set", 0), lambda: game("set", 1, marker="red")):
            with self.assertRaises(ValueError):
                bad()
        o = odometry(mice=(1, 2, 3, 4))
        self.assertEqual(o["mice"], {"x_left": 1.0, "y_left": 2.0, "x_right": 3.0, "y_right": 4.0})
        self.assertIsNone(o["wheels"])
        with self.assertRaises(ValueError):
            odometry(mice=(1, 2, 3))
        with self.assertRaises(ValueError):
            odometry(wheels=[float("inf")])
        self.assertEqual(sonar(0.5, None), {"bearing": 0.5, "range": None})
        self.assertEqual(pose(1, 2, 3), {"x": 1.0, "y": 2.0, "theta": 3.0})

    def test_rgb8(self) -> None:
        array = np.zeros((2, 3, 3), np.uint8)
        array[1, 2] = (1, 2, 3)
        image = rgb8_image(3, 2, array)
        self.assertEqual(image["encoding"], "rgb8")
        data = base64.b64decode(image["data"], validate=True)
        self.assertEqual(len(data), 18)
        self.assertEqual(data[-3:], bytes([1, 2, 3]))  # rows from the top, red first
        self.assertEqual(rgb8_image(3, 2, data), image)
        with self.assertRaises(ValueError):
            rgb8_image(3, 2, data[:-1])
        with self.assertRaises(ValueError):
            rgb8_image(2, 3, array)
        with self.assertRaises(ValueError):
            rgb8_image(0, 2, b"")
        with self.assertRaises(ValueError):
            rgb8_image(3, 2, array.astype(np.float32))

    def test_jpeg(self) -> None:
        array = np.full((24, 32, 3), (30, 130, 50), np.uint8)
        for source in (array, Image.fromarray(array)):
            image = jpeg_image(source, quality=80)
            self.assertEqual((image["width"], image["height"], image["encoding"]), (32, 24, "jpeg"))
            with Image.open(io.BytesIO(base64.b64decode(image["data"]))) as decoded:
                self.assertEqual((decoded.format, decoded.size), ("JPEG", (32, 24)))
                pixel = decoded.convert("RGB").getpixel((5, 5))
                self.assertLess(max(abs(a - b) for a, b in zip(pixel, (30, 130, 50), strict=True)), 6)

    def test_jpeg_keeps_a_small_ball_orange(self) -> None:
        # A ball 5 pixels across on the carpet, as one 11 m away, keeps its colour (with the
        # colour at half resolution, 4:2:0, its pixels are off by 29 a channel on average).
        array = np.full((24, 32, 3), (30, 130, 50), np.uint8)
        rows, cols = np.ogrid[:24, :32]
        ball = (rows - 11.5) ** 2 + (cols - 15.5) ** 2 <= 6.25
        array[ball] = (230, 90, 20)
        image = jpeg_image(array, quality=90)
        with Image.open(io.BytesIO(base64.b64decode(image["data"]))) as decoded:
            got = np.asarray(decoded.convert("RGB")).astype(int)[ball]
        self.assertLess(float(np.abs(got - (230, 90, 20)).mean()), 10.0)

    def test_encode_is_compact_and_refuses_nan(self) -> None:
        self.assertEqual(encode({"a": [1, 2]}), b'{"a":[1,2]}')
        with self.assertRaises(ValueError):
            encode({"a": float("nan")})

    def test_senses_follow_the_schema(self) -> None:
        validator = schema_validator("sense")
        validator.validate(full_sense())
        validator.validate(
            {"protocol": 1, "world": "w", "run": "r", "robot": "x", **sense(0, 0.0, game("playing", 1))}
        )
        validator.validate(json.loads(encode(full_sense())))
        oracle = full_sense()
        objects = {"ball": seen(2.0, 0.1), "west_net": None, "landmarks": [None, seen(4.0, -1.0)]}
        oracle["camera"] = camera(0.3, None, objects=objects)
        validator.validate(oracle)
        with self.assertRaises(ValueError):
            camera(0.3, None)
        with self.assertRaises(ValueError):
            seen(-1.0, 0.0)
        bad = full_sense()
        bad["game"]["state"] = "paused"
        self.assertFalse(validator.is_valid(bad))


class ParseAct(unittest.TestCase):
    def parse(self, data: bytes, step: int | None = 7) -> dict:
        return parse_act(data, "w", "abc", "r1", step)

    def test_good(self) -> None:
        a = self.parse(act())
        self.assertEqual(a["wheels"], [1.0, -2.0])
        self.assertIsInstance(a["wheels"][1], float)
        self.assertEqual(a["twist"], {"vx": 0.1, "vy": 0.0, "omega": 0.2})
        minimal = self.parse(act(wheels=..., twist=..., pan=...))
        self.assertEqual((minimal["wheels"], minimal["twist"], minimal["pan"]), (None, None, None))
        self.assertEqual(self.parse(act(step=9), step=None)["step"], 9)
        self.assertEqual(
            self.parse(act(wheels=None, twist=None, pan=None, faults=["x.lua:3: boom"]))["faults"],
            ["x.lua:3: boom"],
        )

    def test_good_acts_follow_the_schema(self) -> None:
        validator = schema_validator("act")
        validator.validate(self.parse(act()))
        validator.validate(json.loads(act(wheels=None, twist=None, pan=None)))

    def test_bad(self) -> None:
        cases = {
            b"{not json": "malformed",
            b"\xff\xfe": "malformed",
            b"[1, 2]": "malformed",
            b'{"protocol": NaN}': "malformed",
            act(protocol=2): "protocol",
            act(protocol=True): "protocol",
            act(protocol=...): "protocol",
            act(world="v"): "stranger",
            act(run="abd"): "stranger",
            act(robot="r2"): "stranger",
            act(robot=...): "malformed",
            act(step=6): "stale",
            act(step=8): "future",
            act(step=-1): "malformed",
            act(step=7.0): "malformed",
            act(step="7"): "malformed",
            act(wheels=[1.0, "2"]): "malformed",
            act(wheels=[True]): "malformed",
            act(wheels=1.0): "malformed",
            act(twist={"vx": 1.0, "vy": 0.0}): "malformed",
            act(twist=[0, 0, 0]): "malformed",
            act(kick=...): "malformed",
            act(kick=0): "malformed",
            act(pan="left"): "malformed",
            act(faults=...): "malformed",
            act(faults=[1]): "malformed",
            act(wheels=[1e400]): "malformed",  # json.dumps writes Infinity
            b" " * (32 * 1024 * 1024 + 1): "too_large",
        }
        for data, reason in cases.items():
            with self.subTest(data=data[:80]), self.assertRaises(ProtocolError) as caught:
                self.parse(data)
            self.assertEqual(caught.exception.reason, reason)
            self.assertIsInstance(caught.exception, ValueError)


class ParseBye(unittest.TestCase):
    def bye(self, **changes) -> bytes:
        message = {
            "protocol": 1,
            "world": "w",
            "run": "abc",
            "robot": "r1",
            "steps": 10,
            "faults": [
                {"name": "behavior-1", "count": 3, "never_ran": False, "error": "go2ball.lua:3: boom"}
            ],
            "dropped": {
                k: 0 for k in ("malformed", "too_large", "protocol", "stranger", "out_of_order", "clock")
            },
        }
        message.update(changes)
        return json.dumps(message).encode()

    def test_good_and_bad(self) -> None:
        self.assertEqual(parse_bye(self.bye(), "w", "abc", "r1")["steps"], 10)
        for bad in (
            self.bye(steps=-1),
            self.bye(run="x"),
            self.bye(protocol=2),
            self.bye(faults=[{"name": "b"}]),
            self.bye(dropped={"malformed": 0}),
            b"bye",
        ):
            with self.subTest(bad=bad[:60]), self.assertRaises(ProtocolError):
                parse_bye(bad, "w", "abc", "r1")

    def test_schema(self) -> None:
        schema_validator("bye").validate(json.loads(self.bye()))


if __name__ == "__main__":
    unittest.main()
