"""The MuJoCo world's referee and game controller (no MuJoCo here: it reads poses, decides).

States (docs/devices.md `game.state`): `initial` -> `ready` (the robots walk to their kickoff
poses, each told its own in `game.kickoff_pose`; at most READY_TIME s, or until every robot
stands within READY_TOLERANCE of its place) -> `set` (SET_TIME s; robots not at their place, or
standing on the centre spot, are put there; the ball on the centre spot) -> `playing`. In play:

* a goal (the whole ball over the goal line, between the posts) counts, then `ready` again for
  the kickoff of the team that conceded;
* a ball wholly over a side or end line (not a goal) is put back 0.5 m inside the nearest
  line(s), still (moved along the line when a robot stands there), and play goes on;
* a half is `half` s of play (the clock runs in `playing` only); at half time the teams swap
  the direction they attack and the away team kicks off; after the last half: `finished`.

Teams: home wears magenta and attacks +x (east) in the first half, away cyan and -x. Robot 1
of a team keeps goal. The side-line entry and the formation follow crates/mrt-sim/src/referee.rs
(the field players other than the kicker spread evenly across the field here).
Field frame and sizes as make_scene.py (18 x 12 m, goals 2 m wide).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

LENGTH, WIDTH = 18.0, 12.0  # between the lines
GOAL_WIDTH = 2.0
CENTRE_CIRCLE_RADIUS = 2.0
ROBOT_RADIUS = 0.25
BALL_RADIUS = 0.11

INITIAL_TIME = 1.0  # s in `initial` before the first kickoff
READY_TIME = 10.0  # s at most in `ready`
SET_TIME = 1.0  # s in `set`
READY_TOLERANCE = 0.3  # m from its kickoff place that counts as there
OUT_INSET = 0.5  # m inside the line where a ball out is put back
ENTRY_SPACING = 1.2  # m between robots entering on the side line
POSSESSION_RANGE = 1.0  # m from the ball within which the closest robot has it

MARKERS = {"home": "magenta", "away": "cyan"}


def team_of(name: str) -> str:
    """`home-2` -> `home`."""
    return name.split("-")[0]


def number_of(name: str) -> int:
    """`home-2` -> 2."""
    return int(name.rsplit("-", 1)[1])


@dataclass
class Decision:
    """What the referee decided in one update: where to put the ball (x, y) and which robots
    where (name -> x, y, heading); `calls` says why, for the log."""

    ball: tuple[float, float] | None = None
    robots: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    calls: list[str] = field(default_factory=list)


@dataclass
class Stats:
    """One team's statistics: kicks that reached the ball, those of them heading into the
    goal mouth, and steps in which the team had the robot closest to the ball."""

    shots: int = 0
    on_target: int = 0
    possession_steps: int = 0


def heads_into_goal(ball, heading: float, line: float, mouth: float) -> bool:
    """Whether the ball at `ball` (x, y), sent along `heading` (rad), crosses the goal line
    x = `line` (m) within `mouth` (m) of the field's axis."""
    c, s = math.cos(heading), math.sin(heading)
    if abs(c) < 1e-9 or (line - ball[0]) * c <= 0.0:
        return False
    return abs(ball[1] + (line - ball[0]) / c * s) < mouth


class Referee:
    """The referee of a match between the robots `names` (home-1.., away-1..).

    `half`: seconds of play a half; `halves`: how many; `start`: `initial` (a match: the
    robots enter, then kick off) or `playing` (play at once, from where the robots and ball
    are); `until_goal`: the match ends at the first goal.
    """

    def __init__(self, names: list[str], half: float = 300.0, halves: int = 2,
                 start: str = "initial", until_goal: bool = False) -> None:
        if start not in ("initial", "playing"):
            raise ValueError(f"start must be initial or playing, not {start!r}")
        self.names = list(names)
        self.half_length = float(half)
        self.halves = int(halves)
        self.until_goal = until_goal
        self.state = start
        self.half = 1
        self.half_play = 0.0  # s of play in this half
        self.play_time = 0.0  # s of play in all
        self.score = {"home": 0, "away": 0}
        self.goals: list[dict] = []
        self.formation: dict[str, tuple[float, float, float]] = {}
        self.kicking: str | None = None
        self.until = INITIAL_TIME if start == "initial" else 0.0  # when initial/ready/set end
        self.stats = {team: Stats() for team in ("home", "away")}

    # ------------------------------------------------------------ the match's statistics

    def shot(self, name: str, ball, heading: float) -> None:
        """Counts robot `name`'s kick that reached the ball at `ball` (x, y) along `heading`
        (rad): a shot, and on target when that line crosses the goal line the robot's team
        attacks between the posts, less the ball's radius (as `mrt sim` counts them)."""
        team = team_of(name)
        s = self.stats[team]
        s.shots += 1
        line = self.attack(team) * LENGTH / 2
        if heads_into_goal(ball, heading, line, GOAL_WIDTH / 2 - BALL_RADIUS):
            s.on_target += 1

    def account(self, ball, poses) -> None:
        """Counts one step's possession: the team of the robot closest to the ball, if it is
        within POSSESSION_RANGE m of the ball's centre."""
        best = None
        for n, p in poses.items():
            d = math.hypot(p[0] - ball[0], p[1] - ball[1])
            if d < POSSESSION_RANGE and (best is None or d < best[0]):
                best = (d, team_of(n))
        if best is not None:
            self.stats[best[1]].possession_steps += 1

    # ------------------------------------------------------------ what the robots are told

    def attack(self, team: str) -> int:
        """+1: `team` attacks towards +x (east) now; -1: towards -x."""
        home_east = 1 if self.half % 2 == 1 else -1
        return home_east if team == "home" else -home_east

    def game(self, name: str) -> tuple[str, int, tuple[float, float, float] | None, str]:
        """(state, attack, kickoff pose or None, marker) for robot `name`."""
        team = team_of(name)
        pose = self.formation.get(name) if self.state == "ready" else None
        return self.state, self.attack(team), pose, MARKERS[team]

    # ------------------------------------------------------------ places

    def entry_poses(self) -> dict[str, tuple[float, float, float]]:
        """Where the robots enter at the start: on the south side line, each team in its own
        half, the goalkeeper nearest its goal, facing the field."""
        hl, hw = LENGTH / 2, WIDTH / 2
        out = {}
        for team in ("home", "away"):
            mates = [n for n in self.names if team_of(n) == team]
            step = max(min((hl - 1.0) / max(len(mates), 1), ENTRY_SPACING),
                       2 * ROBOT_RADIUS + 0.05)
            for name in mates:
                k = number_of(name) - 1
                x = max(hl - 0.5 - step * k, ROBOT_RADIUS)
                out[name] = (-self.attack(team) * x, -hw, math.pi / 2)
        return out

    def kickoff_poses(self, kicking: str) -> dict[str, tuple[float, float, float]]:
        """The kickoff formation when `kicking` kicks off: the goalkeeper (robot 1) on its goal
        line's inside, the kicking team's robot 2 behind the ball, the others spread over
        their own half outside the centre circle, all facing the goal they attack."""
        hl = LENGTH / 2
        lim = hl - ROBOT_RADIUS - 0.1
        out = {}
        for team in ("home", "away"):
            mates = [n for n in self.names if team_of(n) == team]
            d = self.attack(team)
            kicker = 1 if team == kicking else 0  # robot 2 of the kicking team is at the ball
            lanes = max(len(mates) - 1 - kicker, 1)  # across the field for the others
            for name in mates:
                k = number_of(name) - 1
                if k == 0:
                    x, y = -d * (hl - 0.5), 0.0
                elif k == 1 and kicker:
                    x, y = -d * (2 * ROBOT_RADIUS + BALL_RADIUS), 0.0
                else:
                    lane = k - 1 - kicker
                    y = (lane - (lanes - 1) / 2) * (WIDTH / (lanes + 1))
                    x = -d * (CENTRE_CIRCLE_RADIUS + 0.5 + lane * 0.8)
                x = max(-lim, min(lim, x))
                out[name] = (x, y, 0.0 if d > 0 else math.pi)
        return out

    @staticmethod
    def clear(x: float, y: float, poses) -> bool:
        """Whether a ball at (x, y) touches no robot (with 5 cm to spare)."""
        return all(math.hypot(x - px, y - py) > ROBOT_RADIUS + BALL_RADIUS + 0.05
                   for px, py, _ in poses.values())

    def out_spot(self, bx: float, by: float, poses) -> tuple[float, float]:
        """Where a ball that left the field at (bx, by) goes: 0.5 m inside the nearest
        line(s), moved along the line until it is clear of the robots."""
        mx, my = LENGTH / 2 - OUT_INSET, WIDTH / 2 - OUT_INSET
        x, y = max(-mx, min(mx, bx)), max(-my, min(my, by))
        along_x = abs(y) >= my  # on a side line's inset: move along x
        for k in range(40):
            shift = 0.3 * ((k + 1) // 2) * (1 if k % 2 else -1)
            cx = max(-mx, min(mx, x + shift)) if along_x else x
            cy = y if along_x else max(-my, min(my, y + shift))
            if self.clear(cx, cy, poses):
                return cx, cy
        return x, y

    def centre_spot(self, poses) -> tuple[float, float]:
        """The centre spot, or beside it (along y) while a robot stands on it."""
        for k in range(40):
            y = 0.3 * ((k + 1) // 2) * (1 if k % 2 else -1)
            if self.clear(0.0, y, poses):
                return 0.0, y
        return 0.0, 0.0

    # ------------------------------------------------------------ the rules

    def kickoff(self, kicking: str, now: float, poses, decision: Decision) -> None:
        """`ready` for a kickoff by `kicking`; the ball on the centre spot (beside it while a
        robot stands there: it goes on the spot when READY ends)."""
        self.kicking = kicking
        self.formation = self.kickoff_poses(kicking)
        self.state = "ready"
        self.until = now + READY_TIME
        decision.ball = self.centre_spot(poses)
        decision.calls.append(f"ready: kickoff {kicking}")

    def update(self, now: float, dt: float, ball, poses) -> Decision:
        """The rules after the world advanced by `dt` s to `now` (s) in the current state:
        `ball` (x, y) is the ball's centre, `poses` each robot's (x, y, heading)."""
        decision = Decision()
        bx, by = ball[0], ball[1]
        if self.state == "finished":
            return decision
        if self.state == "initial":
            if now + 1e-9 >= self.until:
                self.kickoff("home", now, poses, decision)
            return decision
        if self.state == "ready":
            there = all(math.hypot(poses[n][0] - p[0], poses[n][1] - p[1]) <= READY_TOLERANCE
                        for n, p in self.formation.items())
            if there or now + 1e-9 >= self.until:
                # Robots not at their place are put there, and so is one on the centre spot.
                for n, p in self.formation.items():
                    if (math.hypot(poses[n][0] - p[0], poses[n][1] - p[1]) > READY_TOLERANCE
                            or not self.clear(0.0, 0.0, {n: poses[n]})):
                        decision.robots[n] = p
                decision.ball = (0.0, 0.0)
                self.state, self.until = "set", now + SET_TIME
                decision.calls.append(f"set ({len(decision.robots)} robots placed)")
            return decision
        if self.state == "set":
            if now + 1e-9 >= self.until:
                self.state = "playing"
                decision.calls.append("playing")
            return decision
        # playing
        self.half_play += dt
        self.play_time += dt
        hl, hw = LENGTH / 2, WIDTH / 2
        if abs(bx) > hl + BALL_RADIUS and abs(by) < GOAL_WIDTH / 2:
            scorer = "home" if (1 if bx > 0 else -1) == self.attack("home") else "away"
            self.score[scorer] += 1
            self.goals.append({"team": scorer, "time": round(now, 3),
                               "play_time": round(self.play_time, 3), "half": self.half})
            decision.calls.append(f"goal {scorer} ({self.score['home']}:{self.score['away']})")
            if self.until_goal:
                self.state = "finished"
                decision.calls.append("finished")
                return decision
            self.kickoff("away" if scorer == "home" else "home", now, poses, decision)
        elif abs(bx) > hl + BALL_RADIUS or abs(by) > hw + BALL_RADIUS:
            decision.ball = self.out_spot(bx, by, poses)
            decision.calls.append(f"out at ({bx:.2f}, {by:.2f})")
        if self.half_play >= self.half_length - 1e-9:
            if self.half < self.halves:
                self.half += 1
                self.half_play = 0.0
                decision.calls.append(f"half time, half {self.half}")
                self.kickoff("away" if self.half % 2 == 0 else "home", now, poses, decision)
            else:
                self.state = "finished"
                decision.calls.append("finished")
        return decision
