"""A fake MRT robot for the tests: it speaks the robot's side of docs/devices.md, drops what a
robot refuses (counting by reason) and answers each admitted step."""

from __future__ import annotations

import base64
import io
import json
import math
import queue
import socket
import threading
from collections import Counter
from collections.abc import Callable

import zenoh

from mrt_world import MAX_MESSAGE, act_key, alive_key, bye_key, end_key, sense_key


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nobody listens on now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def peer(listen: str | None = None, connect: str | None = None) -> zenoh.Session:
    """A zenoh peer session on localhost, multicast scouting off."""
    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("scouting/multicast/enabled", "false")
    if listen:
        config.insert_json5("listen/endpoints", json.dumps([listen]))
    if connect:
        config.insert_json5("connect/endpoints", json.dumps([connect]))
    return zenoh.open(config)


def default_answer(step: int) -> dict | None:
    """Drive forward at 10 rad/s a wheel, pan to 0.1 rad."""
    return {
        "wheels": [10.0, 10.0],
        "twist": {"vx": 0.5, "vy": 0.0, "omega": 0.0},
        "kick": step % 10 == 9,
        "pan": 0.1,
    }


def image_ok(image: object) -> bool:
    """Whether an image's bytes decode to its size."""
    from PIL import Image

    if not isinstance(image, dict):
        return False
    try:
        w, h, data = image["width"], image["height"], base64.b64decode(image["data"], validate=True)
        if image["encoding"] == "rgb8":
            return len(data) == w * h * 3
        with Image.open(io.BytesIO(data)) as jpeg:
            jpeg.load()
            return image["encoding"] == "jpeg" and jpeg.size == (w, h)
    except Exception:
        return False


class FakeRobot:
    """Robot ``name`` of ``world``, connecting to ``connect``.

    ``answer(step)`` gives the act's wheels/twist/kick/pan, or None to stay silent; the first
    copy of each step in ``lose`` is ignored as if lost. Repeats of the last answered step get
    the same answer again. ``senses`` and ``acts`` keep the messages, ``cycles`` the steps run.
    ``gate=False``: a naive robot that answers every JSON sense with a step, checking nothing.
    """

    def __init__(
        self,
        world: str,
        name: str,
        connect: str,
        answer: Callable[[int], dict | None] = default_answer,
        lose: set[int] | frozenset[int] = frozenset(),
        gate: bool = True,
    ) -> None:
        self.world, self.name, self.answer, self.lose, self.gate = world, name, answer, set(lose), gate
        self.run: str | None = None
        self.last: tuple[int, float, bytes] | None = None  # step, time, answer
        self.cycles = 0
        self.copies: Counter[int] = Counter()
        self.dropped: Counter[str] = Counter()
        self.senses: list[dict] = []
        self.acts: list[dict] = []
        self.end_message: dict | None = None
        self.ended = threading.Event()
        self._inbox: queue.Queue = queue.Queue()
        self.session = peer(connect=connect)
        put = self._inbox.put
        self.session.declare_subscriber(
            sense_key(world, name), lambda s: put(("sense", s.payload.to_bytes()))
        )
        self.session.declare_subscriber(end_key(world), lambda s: put(("end", s.payload.to_bytes())))
        self.token = self.session.liveliness().declare_token(alive_key(world, name))
        self._thread = threading.Thread(target=self._loop, daemon=True)
        self._thread.start()

    def close(self) -> None:
        """Stop and close the session."""
        self._inbox.put(("stop", b""))
        self._thread.join(5)
        self.session.close()

    def _loop(self) -> None:
        while True:
            kind, payload = self._inbox.get()
            if kind == "stop":
                return
            if kind == "end":
                self._end(payload)
            else:
                reason = self._sense(payload)
                if reason:
                    self.dropped[reason] += 1

    def _sense(self, payload: bytes) -> str | None:
        """Take one sense; returns the reason it was dropped, or None."""
        if len(payload) > MAX_MESSAGE:
            return "too_large"
        try:
            m = json.loads(payload, parse_constant=lambda c: 1 / 0)
            step, time, game = m["step"], m["time"], m["game"]
            assert isinstance(m, dict) and isinstance(step, int) and isinstance(game, dict)
        except Exception:
            return "malformed"
        if not self.gate:
            self.run = self.run or m.get("run")
            return self._act(m)
        if m.get("protocol") != 1:
            return "protocol"
        if m.get("world") != self.world or m.get("robot") != self.name:
            return "stranger"
        if self.run is None and step == 0:
            self.run = m.get("run")
        if m.get("run") != self.run:
            return "stranger"
        self.copies[step] += 1
        if self.last is not None and step == self.last[0]:
            self.session.put(act_key(self.world, self.name), self.last[2])  # a repeat
            return None
        if self.last is not None and step < self.last[0]:
            return "out_of_order"
        previous = None if self.last is None else self.last[1]
        if not isinstance(time, (int, float)) or not math.isfinite(time) or time < 0:
            return "clock"
        if previous is not None and not 0 < time - previous <= 10:
            return "clock"
        for cam in ("camera", "up_camera"):
            if m.get(cam) is not None and not image_ok(m[cam].get("image")):
                return "malformed"
        if step in self.lose and self.copies[step] == 1:
            return None  # lost on the way
        self.senses.append(m)
        return self._act(m)

    def _act(self, m: dict) -> None:
        """Run a cycle for an admitted sense and answer it."""
        step, time = m["step"], m["time"]
        answer = self.answer(step)
        if answer is None:
            return None
        self.cycles += 1
        act = {
            "protocol": 1,
            "world": self.world,
            "run": self.run,
            "robot": self.name,
            "step": step,
            "faults": [],
        }
        act.update(answer)
        self.acts.append(act)
        data = json.dumps(act).encode()
        self.last = (step, float(time), data)
        self.session.put(act_key(self.world, self.name), data)
        return None

    def _end(self, payload: bytes) -> None:
        m = json.loads(payload)
        if m.get("run") != self.run:
            return
        self.end_message = m
        bye = {
            "protocol": 1,
            "world": self.world,
            "run": self.run,
            "robot": self.name,
            "steps": self.cycles,
            "faults": [],
            "dropped": {
                k: self.dropped[k]
                for k in ("malformed", "too_large", "protocol", "stranger", "out_of_order", "clock")
            },
        }
        self.session.put(bye_key(self.world, self.name), json.dumps(bye).encode())
        self.ended.set()
