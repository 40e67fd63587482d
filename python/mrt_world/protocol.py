"""The device protocol, version 1 (docs/devices.md): keys, message builders and parsers.

Builders return plain dicts ready for JSON; units are SI (m, rad, s). ``sense`` leaves out
``protocol``, ``world``, ``run`` and ``robot``: :class:`mrt_world.World` fills them in.
"""

from __future__ import annotations

import base64
import io
import json
import math
import re
from collections.abc import Sequence
from typing import Any

PROTOCOL = 1
"""The protocol version this package speaks."""

MAX_MESSAGE = 32 * 1024 * 1024
"""The largest message a robot accepts, bytes."""

MAX_IMAGE_SIDE = 4096
"""An image's largest width or height, pixels."""

STATES = ("initial", "ready", "set", "playing", "finished")
MARKERS = ("magenta", "cyan")
DROPPED = ("malformed", "too_large", "protocol", "stranger", "out_of_order", "clock")

_NAME = re.compile(r"^[a-z0-9_-]{1,64}$")


class ProtocolError(ValueError):
    """A message that does not follow the protocol; ``reason`` says why, in one word.

    Reasons: ``malformed``, ``too_large``, ``protocol``, ``stranger``, ``stale`` (an earlier
    step than expected) and ``future`` (a later one).
    """

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(f"{reason}: {message}")
        self.reason = reason


# ---------------------------------------------------------------- keys


def check_name(name: str) -> str:
    """Return ``name`` if it is a world's or robot's name (1-64 of ``a-z 0-9 - _``), else raise ValueError."""
    if not isinstance(name, str) or not _NAME.match(name):
        raise ValueError(f"{name!r} is not a name (1-64 characters of a-z 0-9 - _)")
    return name


def _robot_key(world: str, robot: str, last: str) -> str:
    return f"mrt/devices/{PROTOCOL}/{check_name(world)}/{check_name(robot)}/{last}"


def sense_key(world: str, robot: str) -> str:
    """World → robot: one step's readings."""
    return _robot_key(world, robot, "sense")


def act_key(world: str, robot: str) -> str:
    """Robot → world: the answer to one step."""
    return _robot_key(world, robot, "act")


def bye_key(world: str, robot: str) -> str:
    """Robot → world: the robot's last word."""
    return _robot_key(world, robot, "bye")


def alive_key(world: str, robot: str) -> str:
    """The robot's liveliness token."""
    return _robot_key(world, robot, "alive")


def end_key(world: str) -> str:
    """World → all its robots: the match is over."""
    return f"mrt/devices/{PROTOCOL}/{check_name(world)}/end"


# ---------------------------------------------------------------- builders


def _num(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{what} must be a finite number, not {value!r}")
    return float(value)


def _opt_num(value: Any, what: str) -> float | None:
    return None if value is None else _num(value, what)


def pose(x: float, y: float, theta: float) -> dict:
    """A pose in the field frame: m from the centre spot, rad counter-clockwise from +x."""
    return {"x": _num(x, "x"), "y": _num(y, "y"), "theta": _num(theta, "theta")}


def game(state: str, attack: int, kickoff_pose: dict | None = None, marker: str | None = None) -> dict:
    """The game controller's news: referee ``state``, ``attack`` (1: towards +x, -1: towards -x)."""
    if state not in STATES:
        raise ValueError(f"state must be one of {STATES}, not {state!r}")
    if attack not in (1, -1) or isinstance(attack, bool):
        raise ValueError(f"attack must be 1 or -1, not {attack!r}")
    if marker not in (None, *MARKERS):
        raise ValueError(f"marker must be None or one of {MARKERS}, not {marker!r}")
    return {"state": state, "attack": int(attack), "kickoff_pose": kickoff_pose, "marker": marker}


def odometry(
    mice: Sequence[float] | None = None,
    wheels: Sequence[float] | None = None,
    placed: dict | None = None,
) -> dict:
    """Motion since the previous step: ``mice`` = (x_left, y_left, x_right, y_right) in m,
    ``wheels`` each wheel's turn in rad (base order), ``placed`` a :func:`pose` if put down by hand."""
    m = None
    if mice is not None:
        if len(mice) != 4:
            raise ValueError("mice must be (x_left, y_left, x_right, y_right)")
        names = ("x_left", "y_left", "x_right", "y_right")
        m = {n: _num(v, f"mice.{n}") for n, v in zip(names, mice, strict=True)}
    w = None if wheels is None else [_num(v, "wheel turn") for v in wheels]
    return {"mice": m, "wheels": w, "placed": placed}


def _side(n: int, what: str) -> int:
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_IMAGE_SIDE:
        raise ValueError(f"{what} must be 1-{MAX_IMAGE_SIDE} pixels, not {n!r}")
    return n


def rgb8_image(width: int, height: int, data: Any) -> dict:
    """A raw image: rows from the top, 3 bytes a pixel, red first. ``data``: bytes or a uint8
    numpy array of shape (height, width, 3)."""
    _side(width, "width")
    _side(height, "height")
    if not isinstance(data, (bytes, bytearray, memoryview)):
        import numpy as np

        array = np.asarray(data)
        if array.dtype != np.uint8 or array.shape != (height, width, 3):
            raise ValueError(
                f"image must be uint8 of shape ({height}, {width}, 3), not {array.dtype} {array.shape}"
            )
        data = np.ascontiguousarray(array).tobytes()
    if len(data) != width * height * 3:
        raise ValueError(f"rgb8 data must be {width * height * 3} bytes, not {len(data)}")
    return {
        "width": width,
        "height": height,
        "encoding": "rgb8",
        "data": base64.b64encode(data).decode("ascii"),
    }


def jpeg_image(image: Any, quality: int = 90) -> dict:
    """A baseline JPEG image from a PIL image or a uint8 numpy array (height, width, 3), its
    colour at full resolution (4:4:4). The encoder's usual 4:2:0 halves the colour's
    resolution both ways, which washes out small coloured objects: a ball 11 m away, 5
    pixels across, is no longer orange (the images are about a third larger instead)."""
    from PIL import Image

    if not isinstance(image, Image.Image):
        image = Image.fromarray(image)
    image = image.convert("RGB")
    _side(image.width, "width")
    _side(image.height, "height")
    buffer = io.BytesIO()
    image.save(buffer, format="JPEG", quality=quality, subsampling=0)
    data = base64.b64encode(buffer.getvalue()).decode("ascii")
    return {"width": image.width, "height": image.height, "encoding": "jpeg", "data": data}


def camera(
    time: float, image: dict | None, pan: float | None = None, objects: dict | None = None
) -> dict:
    """One front-camera frame taken at world ``time`` (s), the pan joint at ``pan`` (rad, None:
    no joint): its ``image``, or the ``objects`` an object sensor saw (see :func:`seen`)."""
    if image is None and objects is None:
        raise ValueError("a camera frame has an image or objects")
    frame = {"time": _num(time, "camera time"), "pan": _opt_num(pan, "pan"), "image": image}
    if objects is not None:
        frame["objects"] = objects
    return frame


def seen(distance: float, bearing: float) -> dict:
    """One object an object sensor saw: ``distance`` (m) and ``bearing`` (rad, robot frame),
    for ``objects = {"ball": seen(...), "east_net": ..., "west_net": ..., "landmarks": [...],
    "robots": [...]}``."""
    d = _num(distance, "distance")
    if d < 0:
        raise ValueError(f"distance must be >= 0, not {d}")
    return {"distance": d, "bearing": _num(bearing, "bearing")}


def sonar(bearing: float, range: float | None) -> dict:  # noqa: A002 - the protocol's name
    """One sonar: ``bearing`` (rad, robot frame) and ``range`` to the echo (m, None: no echo)."""
    return {"bearing": _num(bearing, "bearing"), "range": _opt_num(range, "range")}


def sense(
    step: int,
    time: float,
    game: dict,
    odometry: dict | None = None,
    camera: dict | None = None,
    up_camera: dict | None = None,
    sonars: Sequence[dict] | None = None,
) -> dict:
    """One step's readings of one robot, without ``protocol``/``world``/``run``/``robot``.

    ``up_camera`` is ``{"image": ...}`` or just the image dict. ``None``: no reading this step.
    """
    if isinstance(step, bool) or not isinstance(step, int) or step < 0:
        raise ValueError(f"step must be an integer >= 0, not {step!r}")
    if up_camera is not None and "image" not in up_camera:
        up_camera = {"image": up_camera}
    return {
        "step": step,
        "time": _num(time, "time"),
        "odometry": odometry,
        "camera": camera,
        "up_camera": up_camera,
        "sonars": None if sonars is None else list(sonars),
        "game": game,
    }


def encode(message: dict) -> bytes:
    """A message as compact UTF-8 JSON (NaN and infinities refused)."""
    return json.dumps(message, separators=(",", ":"), allow_nan=False).encode("utf-8")


# ---------------------------------------------------------------- parsers


def _refuse_constant(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")


def _load(data: bytes) -> dict:
    if len(data) > MAX_MESSAGE:
        raise ProtocolError("too_large", f"{len(data)} bytes, over {MAX_MESSAGE}")
    try:
        message = json.loads(bytes(data).decode("utf-8"), parse_constant=_refuse_constant)
    except (UnicodeDecodeError, ValueError) as e:
        raise ProtocolError("malformed", f"not JSON ({e})") from None
    if not isinstance(message, dict):
        raise ProtocolError("malformed", "not a JSON object")
    return message


def _is_int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool) and v >= 0


def _is_num(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _header(message: dict, world: str, run: str, robot: str) -> None:
    if message.get("protocol") != PROTOCOL or isinstance(message.get("protocol"), bool):
        raise ProtocolError("protocol", f"protocol {message.get('protocol')!r}, not {PROTOCOL}")
    for field in ("world", "run", "robot"):
        if not isinstance(message.get(field), str):
            raise ProtocolError("malformed", f"{field} must be a string")
    got = (message["world"], message["run"], message["robot"])
    if got != (world, run, robot):
        raise ProtocolError("stranger", f"world/run/robot {got}, not {(world, run, robot)}")


def parse_act(data: bytes, world: str, run: str, robot: str, step: int | None) -> dict:
    """Check an act from ``robot`` of ``world``'s ``run`` answering ``step`` (None: any step).

    Returns it with every optional field present (``wheels``, ``twist``, ``pan`` None when
    missing, wheels as floats); raises :class:`ProtocolError` when it cannot be used.
    """
    m = _load(data)
    _header(m, world, run, robot)
    if not _is_int(m.get("step")):
        raise ProtocolError("malformed", "step must be an integer >= 0")
    if step is not None and m["step"] != step:
        raise ProtocolError("stale" if m["step"] < step else "future", f"step {m['step']}, not {step}")
    wheels = m.get("wheels")
    if wheels is not None and not (isinstance(wheels, list) and all(_is_num(w) for w in wheels)):
        raise ProtocolError("malformed", "wheels must be a list of finite numbers or null")
    twist = m.get("twist")
    if twist is not None and not (
        isinstance(twist, dict) and all(_is_num(twist.get(k)) for k in ("vx", "vy", "omega"))
    ):
        raise ProtocolError("malformed", "twist must be {vx, vy, omega} of finite numbers or null")
    if not isinstance(m.get("kick"), bool):
        raise ProtocolError("malformed", "kick must be true or false")
    pan = m.get("pan")
    if pan is not None and not _is_num(pan):
        raise ProtocolError("malformed", "pan must be a finite number or null")
    faults = m.get("faults")
    if not (isinstance(faults, list) and all(isinstance(f, str) for f in faults)):
        raise ProtocolError("malformed", "faults must be a list of strings")
    return {
        "protocol": PROTOCOL,
        "world": world,
        "run": run,
        "robot": robot,
        "step": m["step"],
        "wheels": None if wheels is None else [float(w) for w in wheels],
        "twist": None if twist is None else {k: float(twist[k]) for k in ("vx", "vy", "omega")},
        "kick": m["kick"],
        "pan": None if pan is None else float(pan),
        "faults": list(faults),
    }


def parse_bye(data: bytes, world: str, run: str, robot: str) -> dict:
    """Check a bye from ``robot`` of ``world``'s ``run``.

    Raises :class:`ProtocolError` when it cannot be used."""
    m = _load(data)
    _header(m, world, run, robot)
    if not _is_int(m.get("steps")):
        raise ProtocolError("malformed", "steps must be an integer >= 0")
    faults = m.get("faults")
    fault_ok = lambda f: (  # noqa: E731
        isinstance(f, dict)
        and isinstance(f.get("name"), str)
        and _is_int(f.get("count"))
        and isinstance(f.get("never_ran"), bool)
        and isinstance(f.get("error"), str)
    )
    if not (isinstance(faults, list) and all(fault_ok(f) for f in faults)):
        raise ProtocolError("malformed", "faults must be a list of {name, count, never_ran, error}")
    dropped = m.get("dropped")
    if not (isinstance(dropped, dict) and all(_is_int(dropped.get(k)) for k in DROPPED)):
        raise ProtocolError("malformed", f"dropped must hold the counts {DROPPED}")
    return m
