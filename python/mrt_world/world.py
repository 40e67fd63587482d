"""A world's side of the device protocol over zenoh: lock-step, resends, the safe command."""

from __future__ import annotations

import json
import math
import queue
import secrets
import threading
import time as _time
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import zenoh

from .protocol import (
    PROTOCOL,
    ProtocolError,
    act_key,
    bye_key,
    check_name,
    encode,
    end_key,
    parse_act,
    parse_bye,
    sense_key,
)

_BLOCK = zenoh.CongestionControl.BLOCK

HOLD = 0.5
"""Seconds of world time without an answer after which a robot's wheels are stopped."""


@dataclass(frozen=True)
class Command:
    """What to apply to one robot now (see :meth:`World.command`).

    ``wheels``: each wheel's speed set-point, rad/s (None: no set-point known yet, keep the base
    still); ``twist``: ``{vx, vy, omega}`` (m/s, rad/s) or None; ``pan``: the pan set-point, rad
    (None: leave the joint); ``kick``: fire the kicker now; ``stopped``: the safe command holds.
    """

    wheels: list[float] | None
    twist: dict | None
    pan: float | None
    kick: bool
    stopped: bool


class World:
    """A world named ``name`` driving ``robots`` over a zenoh peer session.

    ``listen``/``connect``: zenoh endpoints such as ``"tcp/127.0.0.1:7470"`` (given either,
    multicast scouting is off). ``run``: the run id (default: 12 random hex digits).

    Steps are numbered by the World: 0, 1, 2, ... ; a sense passed to :meth:`step` may leave
    ``step`` out, and if it has one it must be the World's next (``world.steps``). ``time`` is
    the caller's: the world's clock, later than the previous step's by more than 0 and at most
    10 s. ``self.dropped`` counts the robots' messages that could not be used, by reason.
    """

    def __init__(
        self,
        name: str,
        robots: Sequence[str],
        listen: Sequence[str] | None = None,
        connect: Sequence[str] | None = None,
        run: str | None = None,
        hold: float = HOLD,
    ) -> None:
        self.name = check_name(name)
        self.robots = [check_name(r) for r in robots]
        if len(set(self.robots)) != len(self.robots):
            raise ValueError(f"robots named twice in {self.robots}")
        self.run = run if run is not None else secrets.token_hex(6)
        if not isinstance(self.run, str) or not 1 <= len(self.run) <= 64:
            raise ValueError("run must be 1-64 characters")
        self.hold = hold
        self.steps = 0
        """Steps sent so far: the next step's number."""
        self.time: float | None = None
        """The latest step's world time, s."""
        self.dropped: Counter[str] = Counter()
        self._queue: queue.Queue[tuple[str, str, bytes]] = queue.Queue()
        self._alive: set[str] = set()
        self._alive_changed = threading.Condition()
        self._byes: dict[str, dict] = {}
        self._sent_now: set[str] = set()
        self._answered_now: set[str] = set()
        self._answered: dict[str, float] = {}  # robot -> time of its latest answered step
        self._latest: dict[str, dict] = {}  # robot -> its latest act
        self._wheels: dict[str, tuple[list[float], dict | None]] = {}
        self._pan: dict[str, float] = {}

        config = zenoh.Config()
        config.insert_json5("mode", '"peer"')
        if listen:
            config.insert_json5("listen/endpoints", json.dumps(list(listen)))
        if connect:
            config.insert_json5("connect/endpoints", json.dumps(list(connect)))
        if listen or connect:
            config.insert_json5("scouting/multicast/enabled", "false")
        self.session = zenoh.open(config)
        self._subscribers = []
        for robot in self.robots:
            for kind, key in (("act", act_key(name, robot)), ("bye", bye_key(name, robot))):
                callback = lambda sample, k=kind, r=robot: self._queue.put((k, r, sample.payload.to_bytes()))  # noqa: E731
                self._subscribers.append(self.session.declare_subscriber(key, callback))
        alive = f"mrt/devices/{PROTOCOL}/{name}/*/alive"
        self._subscribers.append(
            self.session.liveliness().declare_subscriber(alive, self._on_alive, history=True)
        )
        # Held while the world runs: its robots end as soon as it is gone.
        self._world_token = self.session.liveliness().declare_token(
            f"mrt/devices/{PROTOCOL}/{name}/alive"
        )

    # ------------------------------------------------------------ session

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Close the zenoh session (idempotent)."""
        if not self.session.is_closed():
            for subscriber in self._subscribers:
                subscriber.undeclare()
            self._subscribers.clear()
            self._world_token.undeclare()
            self.session.close()

    def _on_alive(self, sample: zenoh.Sample) -> None:
        robot = str(sample.key_expr).split("/")[4]
        with self._alive_changed:
            if sample.kind == zenoh.SampleKind.PUT:
                self._alive.add(robot)
            else:
                self._alive.discard(robot)
            self._alive_changed.notify_all()

    @property
    def alive(self) -> set[str]:
        """The robots whose liveliness token is present now."""
        with self._alive_changed:
            return set(self._alive)

    def wait_for_robots(self, timeout: float) -> None:
        """Wait until every robot's liveliness token is present; TimeoutError names the missing ones."""
        with self._alive_changed:
            if not self._alive_changed.wait_for(lambda: self._alive.issuperset(self.robots), timeout):
                missing = sorted(set(self.robots) - self._alive)
                raise TimeoutError(f"no liveliness token after {timeout} s from: {', '.join(missing)}")

    # ------------------------------------------------------------ steps

    def put_sense_bytes(self, robot: str, payload: bytes) -> None:
        """Put raw bytes on ``robot``'s sense key (also for tests of a robot's robustness).

        Blocks rather than drops on congestion: zenoh drops a large message's fragments
        otherwise, and in lock-step every sense matters."""
        self.session.put(sense_key(self.name, robot), payload, congestion_control=_BLOCK)

    def step(
        self, senses: dict[str, dict], timeout: float = 5.0, resend: float = 1.0
    ) -> dict[str, dict | None]:
        """Send one step's senses (robot -> :func:`~mrt_world.sense` dict) and wait for the acts.

        Every robot in ``senses`` gets its sense (re-sent every ``resend`` s while its answer is
        missing); returns robot -> its checked act, or None when none came within ``timeout`` s.
        """
        if not senses:
            raise ValueError("a step needs at least one sense")
        unknown = set(senses) - set(self.robots)
        if unknown:
            raise ValueError(f"not robots of this world: {sorted(unknown)}")
        times = {s.get("time") for s in senses.values()}
        if len(times) != 1:
            raise ValueError(f"one step has one time, not {times}")
        now = times.pop()
        if isinstance(now, bool) or not isinstance(now, (int, float)) or not math.isfinite(now) or now < 0:
            raise ValueError(f"time must be finite and >= 0, not {now!r}")
        if self.time is not None and not 0 < now - self.time <= 10.0:
            raise ValueError(f"time {now} must be later than {self.time} by more than 0 and at most 10 s")
        k = self.steps
        payloads = {}
        for robot, s in senses.items():
            if s.get("step", k) != k:
                raise ValueError(
                    f"the sense for {robot} has step {s.get('step')}, the World's next step is {k}"
                )
            message = {
                "protocol": PROTOCOL,
                "world": self.name,
                "run": self.run,
                "robot": robot,
                **s,
                "step": k,
            }
            payloads[robot] = encode(message)
        self.steps, self.time = k + 1, float(now)
        self._sent_now, self._answered_now = set(senses), set()
        answers: dict[str, dict | None] = dict.fromkeys(senses)
        start = _time.monotonic()
        next_send = {}
        for robot, payload in payloads.items():
            self.put_sense_bytes(robot, payload)
            next_send[robot] = start + resend
        deadline = start + timeout
        while True:
            pending = [r for r in senses if r not in self._answered_now]
            clock = _time.monotonic()
            if not pending or clock >= deadline:
                break
            for robot in pending:
                if clock >= next_send[robot]:
                    self.put_sense_bytes(robot, payloads[robot])
                    next_send[robot] = clock + resend
            wake = min([deadline] + [next_send[r] for r in pending])
            try:
                item = self._queue.get(timeout=max(0.0, wake - clock))
            except queue.Empty:
                continue
            robot, act = self._handle(item)
            if act is not None:
                answers[robot] = act
        return answers

    def _handle(self, item: tuple[str, str, bytes], accept: bool = True) -> tuple[str, dict | None]:
        """Take one message of a robot; returns (robot, act) for a new answer to the latest step."""
        kind, robot, payload = item
        try:
            if kind == "bye":
                self._byes[robot] = parse_bye(payload, self.name, self.run, robot)
                return robot, None
            act = parse_act(payload, self.name, self.run, robot, self.steps - 1)
        except ProtocolError as e:
            self.dropped[e.reason] += 1
            return robot, None
        if robot not in self._sent_now:
            self.dropped["unasked"] += 1
            return robot, None
        if robot in self._answered_now:
            self.dropped["duplicate"] += 1
            return robot, None
        if not accept:
            self.dropped["late"] += 1
            return robot, None
        self._answered_now.add(robot)
        self._answered[robot] = self.time
        self._latest[robot] = act
        if act["wheels"] is not None:
            self._wheels[robot] = (act["wheels"], act["twist"])
        if act["pan"] is not None:
            self._pan[robot] = act["pan"]
        return robot, act

    def drain(self, seconds: float) -> list[tuple[str, str]]:
        """Take the robots' messages for ``seconds`` without sending a step: acts are not
        answers now (late or repeated ones, or answers to something else). Returns the
        (robot, reason) of each act dropped meanwhile (also counted in ``self.dropped``)."""
        dropped: list[tuple[str, str]] = []
        end = _time.monotonic() + seconds
        while (left := end - _time.monotonic()) > 0:
            try:
                item = self._queue.get(timeout=left)
            except queue.Empty:
                break
            before = self.dropped.copy()
            self._handle(item, accept=False)
            dropped += [(item[1], reason) for reason in (self.dropped - before)]
        return dropped

    def command(self, robot: str) -> Command:
        """The command to apply to ``robot`` now: its last answer's wheel set-points (the
        previous ones when that answer had none) and pan, its kick if it answered the latest
        step; the wheels stopped (all zeros) once its latest answer is more than ``hold`` s
        of world time older than the latest step, or before any answer."""
        if robot not in self.robots:
            raise ValueError(f"{robot!r} is not a robot of this world")
        answered = self._answered.get(robot)
        wheels, twist = self._wheels.get(robot, (None, None))
        pan = self._pan.get(robot)
        if answered is None or self.time is None or self.time - answered > self.hold + 1e-9:
            zeros = None if wheels is None else [0.0] * len(wheels)
            return Command(zeros, {"vx": 0.0, "vy": 0.0, "omega": 0.0}, pan, False, True)
        kick = robot in self._answered_now and self._latest[robot]["kick"]
        return Command(list(wheels) if wheels is not None else None, twist, pan, kick, False)

    # ------------------------------------------------------------ end

    def end(self, timeout: float = 5.0) -> dict[str, dict | None]:
        """End the match: put the end message and wait up to ``timeout`` s for every robot's
        bye. Returns robot -> its checked bye, or None."""
        message = {"protocol": PROTOCOL, "world": self.name, "run": self.run, "steps": self.steps}
        self.session.put(end_key(self.name), encode(message), congestion_control=_BLOCK)
        deadline = _time.monotonic() + timeout
        while not set(self.robots) <= set(self._byes) and (left := deadline - _time.monotonic()) > 0:
            try:
                self._handle(self._queue.get(timeout=left), accept=False)
            except queue.Empty:
                break
        return {robot: self._byes.get(robot) for robot in self.robots}
