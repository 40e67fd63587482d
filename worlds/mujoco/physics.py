"""The MuJoCo world's physics: the robots' bodies and motors, their encoders, mice, sonars and
kicker, and the ball on the carpet.

The scene's robots are mocap bodies (`home0`, ..., `away0`, ...; render_frames.py places them
by hand). :func:`edit_scene` turns the ones in play into driven bodies when the scene is
loaded, in its MjSpec (field.xml is not changed):

* each gets three planar joints, `<robot>_x`, `<robot>_y` (slides) and `<robot>_yaw` (a hinge
  about z), a mass of 30 kg and a site `<robot>_base` at its centre;
* three velocity servos on that site drive it as a differential base does: `<robot>_drive`
  pushes along its heading towards the forward speed the wheels ask for, `<robot>_slip` holds
  its sideways speed at 0 (the wheels' grip), `<robot>_turn` turns it at the wheels' rate. Each
  is limited to the force (torque) the wheels' grip gives, so MuJoCo's contacts decide what
  happens at a wall, a goal, another robot or the ball: a robot driven into a wall stops there;
* the robots do not touch the carpet (contype/conaffinity bits), the ball does;
* the ball rolls with a viscous damping of BALL_DAMPING (1/s) and a little dry friction
  (BALL_STOP_DECEL) that stops it: both on its angular degrees of freedom (set on the
  compiled model by :class:`Physics`), which rolling couples to its motion.

Robots not in play are deleted from the spec. Units: SI; the field frame of make_scene.py.

Sensors are computed from the body's ACTUAL motion over a step (not from the set-points),
with the errors of :class:`SensorErrors` when a match asks for them:
the encoders by the differential drive's inverse kinematics of the displacement (a robot
stuck at a wall reports (nearly) no turn of its wheels; a sideways shove is invisible to
them), the two mice by the arc model of docs/devices.md (crates/mrt-perception/src/mice.rs,
`readings_for`), which the robot inverts exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

# --- the IANUS3 base (crates/mrt-plan/src/kinematics.rs, DiffDriveParams::IANUS3) ----------
WHEEL_RADIUS = 0.05  # m
TRACK = 0.40  # m between the wheels
TOP_WHEEL_SPEED = 24.0  # rad/s
TOP_WHEEL_ACCEL = 60.0  # rad/s^2
ROBOT_MASS = 30.0  # kg (configs/sim/default.toml [body] mass)
GRIP = 0.8 * ROBOT_MASS * 9.81  # N: the most the wheels can push (or hold sideways)
SERVO_TIME = 0.02  # s: how fast the body follows its wheels (velocity servo gain m / this)
STALL_SLIP = 2.0  # rad/s: the most a wheel's speed runs ahead of the body's motion (a blocked
#                   robot's motors stall instead of spinning on)

# --- sensors and actuators (configs/robot/robot.toml) --------------------------------------
MICE_DISTANCE = 0.2  # m: [sensors] mice_distance
PAN_SPEED = 3.0  # rad/s: [gaze] pan_speed
PAN_LIMIT = 1.5  # rad: [gaze] pan_min / pan_max
KICK_SPEED = 6.0  # m/s
KICK_REACH = 0.12  # m in front of the robot's edge ([body] kick_reach)
KICK_HALF_ANGLE = 0.4  # rad either side of the heading
KICK_RECHARGE = 1.0  # s between two kicks
SONARS = 16  # in a ring, the first straight ahead, counter-clockwise
SONAR_HEIGHT = 0.2  # m above the floor
SONAR_RANGE = 3.0  # m from the robot's centre; farther: no echo

# --- the ball on the carpet -------------------------------------------------------------------
BALL_DAMPING = 0.4  # 1/s ([ball] rolling_damping): a ball rolled at v stops after ~v/0.4 m
BALL_STOP_DECEL = 0.02  # m/s^2: the carpet's dry friction, which stops a slow ball

CARPET_BITS = 2  # contype/conaffinity of the carpet; the ball has 1|2, robots and walls 1
TEAMS = ("home", "away")


# --- kinematics ------------------------------------------------------------------------------


def sinc(x: float) -> float:
    """sin(x) / x, 1 at 0 (mrt_core::sinc)."""
    if abs(x) < 1e-4:
        x2 = x * x
        return 1.0 - x2 / 6.0 + x2 * x2 / 120.0
    return math.sin(x) / x


def arc_velocity(dx: float, dy: float, dtheta: float) -> tuple[float, float]:
    """The constant body velocity (per unit time, robot frame at the start) that moves the robot
    by (dx, dy) while it turns by dtheta along an arc (mrt_core::arc_velocity)."""
    s, c = math.sin(0.5 * dtheta), math.cos(0.5 * dtheta)
    k = 1.0 / sinc(0.5 * dtheta)
    return k * (c * dx + s * dy), k * (-s * dx + c * dy)


def wheels_twist(left: float, right: float) -> tuple[float, float]:
    """Wheel speeds (rad/s) -> the body's forward speed (m/s) and turn rate (rad/s)."""
    return WHEEL_RADIUS * (left + right) / 2.0, WHEEL_RADIUS * (right - left) / TRACK


def ramp(current: list[float], target: list[float], dt: float) -> list[float]:
    """One step from `current` towards `target` wheel speeds (the target first scaled into the
    top speed as a whole), no wheel changing by more than TOP_WHEEL_ACCEL * dt: the change is
    scaled by one factor for both wheels, which keeps the path's curvature (Kinematics::ramp)."""
    target = [t if math.isfinite(t) else 0.0 for t in target]
    top = max(abs(t) for t in target)
    if top > TOP_WHEEL_SPEED:
        target = [t * TOP_WHEEL_SPEED / top for t in target]
    delta = [t - c for t, c in zip(target, current)]
    largest = max(abs(d) for d in delta)
    step = TOP_WHEEL_ACCEL * dt
    if largest <= step:
        return target
    k = step / largest
    return [c + k * d for c, d in zip(current, delta)]


def relative(start: tuple[float, float, float], end: tuple[float, float, float]):
    """The displacement (dx, dy, dtheta) from pose `start` to pose `end`, in the robot frame
    at `start` (theta not wrapped: the hinge's angle is continuous)."""
    x0, y0, t0 = start
    x1, y1, t1 = end
    c, s = math.cos(t0), math.sin(t0)
    ex, ey = x1 - x0, y1 - y0
    return c * ex + s * ey, -s * ex + c * ey, t1 - t0


def wheel_turns(dx: float, dy: float, dtheta: float) -> list[float]:
    """What the encoders count (rad, left then right) for a displacement along an arc: the
    inverse kinematics of its forward motion and turn (the sideways part slips past them)."""
    vx, _ = arc_velocity(dx, dy, dtheta)
    half = 0.5 * TRACK * dtheta
    return [(vx - half) / WHEEL_RADIUS, (vx + half) / WHEEL_RADIUS]


def mice_readings(dx: float, dy: float, dtheta: float, distance: float = MICE_DISTANCE):
    """What the two mice read (x_left, y_left, x_right, y_right; m) for a displacement along an
    arc (docs/devices.md; MiceOdometry::readings_for): the left mouse at (0, +D/2), the right at
    (0, -D/2); each reads its constant velocity in the turning robot frame times the period,
    x̄ = minus the robot's y, ȳ = the robot's x."""
    vx, vy = arc_velocity(dx, dy, dtheta)
    half = 0.5 * distance * dtheta
    return (-vy, vx - half, -vy, vx + half)


# --- the scene ----------------------------------------------------------------------------


def robot_names(home: int, away: int) -> list[tuple[str, str, int]]:
    """(name in the protocol, team, index) of each robot: home-1 is the body home0."""
    return [(f"{team}-{k + 1}", team, k) for team, n in (("home", home), ("away", away))
            for k in range(n)]


def edit_scene(home: int, away: int):
    """An `edit` for render_frames.World (or :func:`compile_scene`): the MjSpec changes of the
    module doc for `home` and `away` robots in play."""

    def edit(spec):
        import mujoco as mj

        _contacts(spec)
        for team, n in (("home", home), ("away", away)):
            existing = 0
            while _find_body(spec, f"{team}{existing}") is not None:
                existing += 1
            for k in range(existing, n):  # more robots than the scene has: copies of robot 0
                _copy_robot(spec, team, k)
            for k in range(n):
                _drive(spec, mj, _find_body(spec, f"{team}{k}"), f"{team}{k}")
            for k in range(n, existing):
                spec.delete(_find_body(spec, f"{team}{k}"))
        spec.option.integrator = mj.mjtIntegrator.mjINT_IMPLICITFAST

    return edit


def compile_scene(scene, home: int, away: int):
    """The scene's model and data with the robots in play driven (no renderer)."""
    import mujoco as mj

    spec = mj.MjSpec.from_file(str(scene))
    edit_scene(home, away)(spec)
    model = spec.compile()
    return model, mj.MjData(model)


def _find_body(spec, name):
    try:
        return spec.body(name)
    except Exception:  # noqa: BLE001 - MuJoCo versions differ: None or an error
        return None


def _contacts(spec):
    carpet = spec.geom("carpet")
    carpet.contype = carpet.conaffinity = CARPET_BITS
    ball = spec.geom("ball")
    ball.contype = ball.conaffinity = 1 | CARPET_BITS


def _copy_robot(spec, team, k):
    template = spec.body(f"{team}0")
    body = spec.worldbody.add_body(name=f"{team}{k}", mocap=True, pos=[2.0 * k, 0, -10])
    for j, g in enumerate(template.geoms):
        body.add_geom(name=f"{team}{k}_{j}", type=g.type, size=list(g.size), pos=list(g.pos),
                      material=g.material)


def _drive(spec, mj, body, name):
    """Planar joints, a mass and the three servos of the module doc on robot body `body`."""
    body.mocap = False
    body.pos = [0.0, 0.0, 0.0]
    body.explicitinertial = True
    body.mass = ROBOT_MASS
    geoms = list(body.geoms)
    radius = float(geoms[0].size[0]) if geoms else 0.25
    izz = 0.5 * ROBOT_MASS * radius * radius
    body.inertia = [izz, izz, izz]
    body.ipos = [0.0, 0.0, 0.3]
    slide, hinge = mj.mjtJoint.mjJNT_SLIDE, mj.mjtJoint.mjJNT_HINGE
    body.add_joint(name=f"{name}_x", type=slide, axis=[1, 0, 0], damping=0.0)
    body.add_joint(name=f"{name}_y", type=slide, axis=[0, 1, 0], damping=0.0)
    body.add_joint(name=f"{name}_yaw", type=hinge, axis=[0, 0, 1], damping=0.0)
    body.add_site(name=f"{name}_base", pos=[0, 0, 0.1])
    for what, gear, kv, limit in (
        ("drive", [1, 0, 0, 0, 0, 0], ROBOT_MASS / SERVO_TIME, GRIP),
        ("slip", [0, 1, 0, 0, 0, 0], 2 * ROBOT_MASS / SERVO_TIME, GRIP),
        ("turn", [0, 0, 0, 0, 0, 1], izz / SERVO_TIME, GRIP * TRACK / 2),
    ):
        a = spec.add_actuator(name=f"{name}_{what}", target=f"{name}_base",
                              trntype=mj.mjtTrn.mjTRN_SITE)
        a.set_to_velocity(kv=kv)
        a.gear = gear
        a.ctrllimited = False
        a.forcelimited = True
        a.forcerange = [-limit, limit]


# --- the physics ------------------------------------------------------------------------------


@dataclass
class Robot:
    """One driven robot: where its joints and servos are, and its motors' state."""

    name: str
    team: str
    body: int
    qpos: int  # x, y, yaw
    dof: int
    actuators: tuple[int, int, int]  # drive, slip, turn
    geoms: list[int]
    radius: float
    setpoint: list[float] = field(default_factory=lambda: [0.0, 0.0])  # rad/s, left, right
    wheels: list[float] = field(default_factory=lambda: [0.0, 0.0])  # rad/s, ramped
    pan: float = 0.0  # rad, the camera's pan joint
    pan_target: float = 0.0
    kick_ready_at: float = 0.0
    kicks: int = 0  # kicks that hit the ball


class Physics:
    """The ball and the driven robots of a compiled scene (:func:`edit_scene`)."""

    def __init__(self, model, data, home: int, away: int, pan: float = 0.0):
        import mujoco as mj

        self.mj, self.model, self.data = mj, model, data
        m = model
        name2id = lambda kind, n: mj.mj_name2id(m, kind, n)  # noqa: E731
        ball = name2id(mj.mjtObj.mjOBJ_JOINT, "ball")
        self.ball_qpos, self.ball_dof = int(m.jnt_qposadr[ball]), int(m.jnt_dofadr[ball])
        self.ball_geom = name2id(mj.mjtObj.mjOBJ_GEOM, "ball")
        self.ball_body = int(m.geom_bodyid[self.ball_geom])
        self.ball_radius = float(m.geom_size[self.ball_geom][0])
        # The ball's damping: with rolling, ω = v / r, an angular damping c gives the force
        # c v / r² on an effective mass m + I / r² = 1.4 m (a solid sphere): rate c / (1.4 m r²).
        mass = float(m.body_mass[self.ball_body])
        inertia = float(m.body_inertia[self.ball_body][0])
        effective = mass + inertia / self.ball_radius ** 2
        m.dof_damping[self.ball_dof:self.ball_dof + 3] = 0.0
        m.dof_damping[self.ball_dof + 3:self.ball_dof + 6] = (
            BALL_DAMPING * effective * self.ball_radius ** 2)
        # A dry friction torque f slows a rolling ball by f / (r * effective mass).
        m.dof_frictionloss[self.ball_dof:self.ball_dof + 3] = 0.0
        m.dof_frictionloss[self.ball_dof + 3:self.ball_dof + 6] = (
            BALL_STOP_DECEL * effective * self.ball_radius)
        self.timestep = float(m.opt.timestep)
        self.time = 0.0
        self.robots: dict[str, Robot] = {}
        for name, team, k in robot_names(home, away):
            body = name2id(mj.mjtObj.mjOBJ_BODY, f"{team}{k}")
            joint = name2id(mj.mjtObj.mjOBJ_JOINT, f"{team}{k}_x")
            if body < 0 or joint < 0:
                raise ValueError(f"the model has no driven robot {team}{k} (edit_scene)")
            geoms = list(range(m.body_geomadr[body], m.body_geomadr[body] + m.body_geomnum[body]))
            acts = tuple(name2id(mj.mjtObj.mjOBJ_ACTUATOR, f"{team}{k}_{w}")
                         for w in ("drive", "slip", "turn"))
            radius = max(float(m.geom_size[g][0]) for g in geoms)
            self.robots[name] = Robot(name, team, body, int(m.jnt_qposadr[joint]),
                                      int(m.jnt_dofadr[joint]), acts, geoms, radius,
                                      pan=pan, pan_target=pan)
        mj.mj_forward(m, data)

    # ------------------------------------------------------------ state

    def pose(self, name: str) -> tuple[float, float, float]:
        """The robot's pose: x, y (m), heading (rad, not wrapped)."""
        q = self.robots[name].qpos
        x, y, t = self.data.qpos[q:q + 3]
        return float(x), float(y), float(t)

    def velocity(self, name: str) -> tuple[float, float, float]:
        """The robot's velocity in the field frame: vx, vy (m/s), omega (rad/s)."""
        v = self.robots[name].dof
        return tuple(float(x) for x in self.data.qvel[v:v + 3])

    def ball(self) -> tuple[float, float, float, float]:
        """The ball's centre x, y (m) and velocity vx, vy (m/s)."""
        q, v = self.ball_qpos, self.ball_dof
        return (float(self.data.qpos[q]), float(self.data.qpos[q + 1]),
                float(self.data.qvel[v]), float(self.data.qvel[v + 1]))

    def place_robot(self, name: str, pose) -> None:
        """Puts the robot down at `pose` (x, y, heading), still, its motors stopped."""
        r = self.robots[name]
        self.data.qpos[r.qpos:r.qpos + 3] = pose
        self.data.qvel[r.dof:r.dof + 3] = 0.0
        r.setpoint, r.wheels = [0.0, 0.0], [0.0, 0.0]
        self.mj.mj_forward(self.model, self.data)

    def place_ball(self, x: float, y: float, vx: float = 0.0, vy: float = 0.0) -> None:
        """Puts the ball on the floor at (x, y), rolling at (vx, vy) (0: still)."""
        q, v = self.ball_qpos, self.ball_dof
        self.data.qpos[q:q + 7] = (x, y, self.ball_radius, 1.0, 0.0, 0.0, 0.0)
        self.data.qvel[v:v + 6] = 0.0
        self.mj.mj_forward(self.model, self.data)
        if vx or vy:
            self.roll_ball(vx, vy)

    def roll_ball(self, vx: float, vy: float) -> None:
        """Sets the ball rolling (without slipping) at (vx, vy) m/s."""
        v = self.ball_dof
        self.data.qvel[v:v + 3] = (vx, vy, 0.0)
        # Rolling: the contact point still, ω × (-r z) = -v, so ω = (-vy, vx, 0) / r in the
        # field frame; a free joint's angular velocity is in the ball's own frame.
        w = np.array([-vy, vx, 0.0]) / self.ball_radius
        rot = self.data.xmat[self.ball_body].reshape(3, 3)
        self.data.qvel[v + 3:v + 6] = rot.T @ w

    def free_spot(self, x: float, y: float, clearance: float) -> bool:
        """Whether a disc of radius `clearance` at (x, y) touches no robot."""
        for name, r in self.robots.items():
            px, py, _ = self.pose(name)
            if math.hypot(px - x, py - y) < r.radius + clearance:
                return False
        return True

    # ------------------------------------------------------------ commands

    def command(self, name: str, wheels=None, pan=None) -> None:
        """The robot's wheel speed set-points (rad/s, left and right; None: keep them) and its
        camera's pan set-point (rad; None: keep it)."""
        r = self.robots[name]
        if wheels is not None:
            if len(wheels) != 2:
                raise ValueError(f"{name}: a differential base has 2 wheels, not {len(wheels)}")
            r.setpoint = [max(-TOP_WHEEL_SPEED, min(TOP_WHEEL_SPEED, float(w)))
                          if math.isfinite(w) else 0.0 for w in wheels]
        if pan is not None and math.isfinite(pan):
            r.pan_target = max(-PAN_LIMIT, min(PAN_LIMIT, float(pan)))

    def kick(self, name: str) -> bool:
        """Fires the robot's kicker (now, at self.time). A charged kicker fires, and recharges
        for KICK_RECHARGE s; the ball leaves at KICK_SPEED along the robot's heading if it lies
        within KICK_REACH of the robot's front edge and KICK_HALF_ANGLE of its heading.
        Returns whether the ball was kicked."""
        r = self.robots[name]
        if self.time + 1e-9 < r.kick_ready_at:
            return False
        r.kick_ready_at = self.time + KICK_RECHARGE
        x, y, t = self.pose(name)
        bx, by, _, _ = self.ball()
        dx, dy = bx - x, by - y
        bearing = math.remainder(math.atan2(dy, dx) - t, 2 * math.pi)
        gap = math.hypot(dx, dy) - r.radius - self.ball_radius
        if gap > KICK_REACH or abs(bearing) > KICK_HALF_ANGLE:
            return False
        self.roll_ball(KICK_SPEED * math.cos(t), KICK_SPEED * math.sin(t))
        r.kicks += 1
        return True

    # ------------------------------------------------------------ time

    def step(self, duration: float) -> None:
        """Advances the physics by `duration` s (whole MuJoCo steps): the wheels ramp towards
        their set-points (never more than STALL_SLIP ahead of the body's motion: a robot
        pushing a wall stalls), the servos drive the bodies, the pan joints turn."""
        n = max(1, round(duration / self.timestep))
        dt = self.timestep
        ctrl = self.data.ctrl
        qvel = self.data.qvel
        for _ in range(n):
            for r in self.robots.values():
                vx, vy, om = qvel[r.dof:r.dof + 3]
                t = self.data.qpos[r.qpos + 2]
                v = math.cos(t) * vx + math.sin(t) * vy
                for i, w in enumerate(((v - om * TRACK / 2) / WHEEL_RADIUS,
                                       (v + om * TRACK / 2) / WHEEL_RADIUS)):
                    r.wheels[i] = max(w - STALL_SLIP, min(w + STALL_SLIP, r.wheels[i]))
                r.wheels = ramp(r.wheels, r.setpoint, dt)
                v, w = wheels_twist(*r.wheels)
                drive, slip, turn = r.actuators
                ctrl[drive], ctrl[slip], ctrl[turn] = v, 0.0, w
            self.mj.mj_step(self.model, self.data)
        for r in self.robots.values():
            step = PAN_SPEED * n * dt
            r.pan += max(-step, min(step, r.pan_target - r.pan))
        self.time += n * dt

    # ------------------------------------------------------------ sensors

    def sonars(self, name: str) -> list[tuple[float, float | None]]:
        """The ring's (bearing, range): each a ray at SONAR_HEIGHT from the robot's centre
        outwards, the robot's own body excluded (so the echo is the first thing beyond its
        edge, even one that touches or dents it); range from the centre, None beyond
        SONAR_RANGE."""
        r = self.robots[name]
        x, y, t = self.pose(name)
        centre = np.array([x, y, SONAR_HEIGHT])
        geom = np.zeros(1, dtype=np.int32)
        out = []
        for i in range(SONARS):
            bearing = 2 * math.pi * i / SONARS
            d = np.array([math.cos(t + bearing), math.sin(t + bearing), 0.0])
            hit = self.mj.mj_ray(self.model, self.data, centre, d, None, 1, r.body, geom)
            out.append((bearing, hit if 0 <= hit <= SONAR_RANGE else None))
        return out


@dataclass
class SensorErrors:
    """What the mice and encoders get wrong, as in MRT's simulator (configs/sim/default.toml,
    [odometry]; MRT manual §4.2): with probability `mice_miss` a mouse under-reads, 50-100 % of
    its motion, then each of its axes is off by `mice_noise` times the motion's length
    (Gaussian); each wheel's count is off by `wheel_noise` of itself (Gaussian)."""

    mice_noise: float = 0.005
    mice_miss: float = 0.02
    wheel_noise: float = 0.05


@dataclass
class Odometer:
    """A robot's encoders and mice between two steps: the pose at the previous reading, and
    the sensors' errors (None: exact readings) drawn from `rng` (a numpy Generator)."""

    start: tuple[float, float, float]
    errors: SensorErrors | None = None
    rng: object = None

    def read(self, now: tuple[float, float, float]):
        """(mice, wheel turns) since the previous reading; then counts from `now`."""
        d = relative(self.start, now)
        self.start = now
        mice, turns = mice_readings(*d), wheel_turns(*d)
        e, rng = self.errors, self.rng
        if e is None or rng is None:
            return mice, turns
        out = []
        for x, y in ((mice[0], mice[1]), (mice[2], mice[3])):
            length = math.hypot(x, y)
            if rng.random() < e.mice_miss:
                read = rng.uniform(0.5, 1.0)
                x, y = x * read, y * read
            spread = e.mice_noise * length
            out += [x + spread * rng.normal(), y + spread * rng.normal()]
        return tuple(out), [t * (1.0 + e.wheel_noise * rng.normal()) for t in turns]
