#!/usr/bin/env python3
"""Writes field.xml: a MuJoCo (MJCF) model of MRT's Middle Size League field.

The numbers are the simulator's defaults (configs/sim/default.toml) and its renderer's
palette (crates/mrt-sim/src/render.rs). Edit them here and run

    python make_scene.py                 # writes field.xml next to this file
    python make_scene.py --robots 6      # six robots a team
    python make_scene.py --out other.xml

or edit field.xml by hand. Metres, z up. Field frame: the origin at the centre spot, +x
towards the east (yellow) goal, +y towards the north side line.

field.xml has no lights: the scene files in scenes/ include it and add them.
Names other tools rely on: the body and geom `ball` (free joint `ball`), the mocap body
`viewer` carrying the camera `eye`, and the mocap bodies `home0`, `home1`, ... and `away0`,
... (the robots), parked under the floor until a tool moves them.
"""

import argparse
import math
from pathlib import Path

# --- the field (configs/sim/default.toml [field]) -------------------------------------------
LENGTH = 18.0  # between the goal lines
WIDTH = 12.0  # between the side lines
BORDER = 1.0  # carpet outside the lines, up to the walls
GOAL_WIDTH = 2.0  # inside
GOAL_DEPTH = 0.6
GOAL_HEIGHT = 1.0
GOAL_WALL = 0.05  # thickness of the goals' back, sides and crossbar
CENTRE_CIRCLE_RADIUS = 2.0
CIRCLE_SEGMENTS = 72  # straight pieces of the centre circle
PENALTY_AREA_DEPTH = 2.25
PENALTY_AREA_WIDTH = 6.5
LINE_WIDTH = 0.1  # centred on the line's nominal position
LINE_TOP = 0.001  # the lines: from the carpet (z = 0) up to this height
LINE_STEP = 0.0001  # the half-way line's top is this much lower, under the centre circle
WALL_HEIGHT = 0.5
WALL_THICKNESS = 0.1  # outside the carpet

# --- objects --------------------------------------------------------------------------------
POST_RADIUS = 0.1
POST_HEIGHT = 0.8  # three equal bands
BALL_RADIUS = 0.11
BALL_MASS = 0.43
ROBOT_RADIUS = 0.25
ROBOT_HEIGHT = 0.6
BAND = (0.48, 0.57)  # the team marker band, heights above the floor
ROBOTS_PER_TEAM = 4  # configs/sim/default.toml [rules] team_size
PARKED_Z = -10.0  # robots wait here, under the floor, until a tool places them

# --- the default camera (configs/vision/camera.toml) ----------------------------------------
CAMERA_HEIGHT = 0.45
CAMERA_TILT_DEG = 20.0
CAMERA_FOVY_DEG = math.degrees(2.0 * math.atan((240 / 2) / 260.0))
VIEWER_AT = (-3.0, 0.0)  # where `viewer` starts, looking east

# --- colours, RGB 0-255 (crates/mrt-sim/src/render.rs, palette) -----------------------------
CARPET = (30, 130, 50)
LINE = (235, 235, 235)
WALL = (140, 140, 140)
YELLOW = (225, 200, 30)
BLUE = (25, 70, 190)
BALL = (250, 110, 15)
ROBOT = (22, 22, 26)
MAGENTA = (200, 40, 190)
CYAN = (40, 190, 210)
HALL = (90, 82, 74)  # the background above the walls (an unlit skybox)

# name: (colour, specular, shininess). The carpet, lines and walls are matte; the ball shines.
MATERIALS = {
    "carpet": (CARPET, 0.0, 0.0),
    "line": (LINE, 0.0, 0.0),
    "wall": (WALL, 0.0, 0.0),
    "goal_yellow": (YELLOW, 0.1, 0.2),
    "goal_blue": (BLUE, 0.1, 0.2),
    "ball": (BALL, 0.5, 0.5),
    "robot": (ROBOT, 0.2, 0.3),
    "marker_home": (MAGENTA, 0.1, 0.2),
    "marker_away": (CYAN, 0.1, 0.2),
}


def f(*values):
    """Numbers as MJCF wants them: space-separated, without needless digits."""
    return " ".join(f"{v:.6g}" if abs(v) >= 1e-12 else "0" for v in values)


def rgb(colour):
    return f(*(c / 255.0 for c in colour))


def rgba(colour):
    return f"{rgb(colour)} 1"


def box(name, x0, x1, y0, y1, z0, z1, material, extra=""):
    """An axis-aligned box from its corners."""
    lo, hi = (min(x0, x1), min(y0, y1), min(z0, z1)), (max(x0, x1), max(y0, y1), max(z0, z1))
    pos = [(a + b) / 2 for a, b in zip(lo, hi)]
    size = [(b - a) / 2 for a, b in zip(lo, hi)]
    return (f'<geom name="{name}" type="box" pos="{f(*pos)}" size="{f(*size)}" '
            f'material="{material}"{extra}/>')


def look_quat(yaw, tilt):
    """The quaternion (w x y z) of a MuJoCo camera frame (looking along -z, +y up) whose
    optical axis has heading `yaw` and points `tilt` rad below the horizontal."""
    fwd = (math.cos(yaw) * math.cos(tilt), math.sin(yaw) * math.cos(tilt), -math.sin(tilt))
    right = (math.sin(yaw), -math.cos(yaw), 0.0)
    up = (right[1] * fwd[2] - right[2] * fwd[1],
          right[2] * fwd[0] - right[0] * fwd[2],
          right[0] * fwd[1] - right[1] * fwd[0])
    back = tuple(-c for c in fwd)
    # Rotation matrix columns: the camera's x (right), y (up), z (back) in the world.
    m = [[right[i], up[i], back[i]] for i in range(3)]
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = (0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s)
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2
        q = ((m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s)
    elif m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2
        q = ((m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s)
    else:
        s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2
        q = ((m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s)
    return q


def field_lines():
    """The white lines: boxes on the carpet that touch but do not overlap (coplanar
    overlapping faces flicker in the depth test and, where a light casts shadows, get its
    light twice), and the centre circle as one flat ring (circle_mesh). The half-way line runs
    under the ring, a step LINE_STEP lower."""
    hl, hw, w = LENGTH / 2, WIDTH / 2, LINE_WIDTH / 2
    lines = [
        ("line_touch_north", (-hl - w, hl + w, hw - w, hw + w), LINE_TOP),
        ("line_touch_south", (-hl - w, hl + w, -hw - w, -hw + w), LINE_TOP),
        ("line_goal_east", (hl - w, hl + w, -hw + w, hw - w), LINE_TOP),
        ("line_goal_west", (-hl - w, -hl + w, -hw + w, hw - w), LINE_TOP),
        ("line_halfway", (-w, w, -hw + w, hw - w), LINE_TOP - LINE_STEP),
    ]
    pd, pw = PENALTY_AREA_DEPTH, PENALTY_AREA_WIDTH / 2
    for side, name in ((1.0, "east"), (-1.0, "west")):
        front = side * (hl - pd)
        lines.append((f"line_penalty_{name}_front", (front - w, front + w, -pw - w, pw + w),
                      LINE_TOP))
        for ys, yname in ((1.0, "north"), (-1.0, "south")):
            lines.append((f"line_penalty_{name}_{yname}",
                          (side * (hl - w), front + side * w, ys * pw - w, ys * pw + w),
                          LINE_TOP))
    out = [box(n, x0, x1, y0, y1, 0.0, z, "line", ' contype="0" conaffinity="0"')
           for n, (x0, x1, y0, y1), z in lines]
    out.append('<geom name="line_circle" type="mesh" mesh="centre_circle" material="line" '
               'contype="0" conaffinity="0"/>')
    return out


def circle_mesh():
    """The centre circle: a ring LINE_WIDTH wide and LINE_TOP high, CIRCLE_SEGMENTS straight
    pieces round, as a closed mesh (top, bottom, inner and outer walls)."""
    r, w, n, h = CENTRE_CIRCLE_RADIUS, LINE_WIDTH / 2, CIRCLE_SEGMENTS, LINE_TOP
    vertices = []
    for k in range(n):
        a = 2 * math.pi * k / n
        c, s = math.cos(a), math.sin(a)
        for radius in (r - w, r + w):
            for z in (0.0, h):
                vertices += [radius * c, radius * s, z]
    faces = []
    for k in range(n):
        # Vertex 4k + 2i + j: inner (i = 0) or outer ring, bottom (j = 0) or top.
        ib, it, ob, ot = (4 * k + d for d in range(4))
        nib, nit, nob, not_ = (4 * ((k + 1) % n) + d for d in range(4))
        faces += [it, ot, not_, it, not_, nit]  # top, facing up
        faces += [ib, nob, ob, ib, nib, nob]  # bottom, facing down
        faces += [ob, nob, not_, ob, not_, ot]  # outer wall, facing out
        faces += [ib, it, nit, ib, nit, nib]  # inner wall, facing in
    return (f'  <mesh name="centre_circle" vertex="{f(*vertices)}" '
            f'face="{" ".join(str(i) for i in faces)}"/>')


def walls():
    hx, hy, t, h = LENGTH / 2 + BORDER, WIDTH / 2 + BORDER, WALL_THICKNESS, WALL_HEIGHT
    return [
        box("wall_east", hx, hx + t, -hy - t, hy + t, 0, h, "wall"),
        box("wall_west", -hx - t, -hx, -hy - t, hy + t, 0, h, "wall"),
        box("wall_north", -hx, hx, hy, hy + t, 0, h, "wall"),
        box("wall_south", -hx, hx, -hy - t, -hy, 0, h, "wall"),
    ]


def goals():
    hl, gd, t, gw, gh = LENGTH / 2, GOAL_DEPTH, GOAL_WALL, GOAL_WIDTH / 2, GOAL_HEIGHT
    out = []
    for s, name, mat in ((1.0, "east", "goal_yellow"), (-1.0, "west", "goal_blue")):
        out += [
            box(f"goal_{name}_back", s * (hl + gd), s * (hl + gd + t), -gw - t, gw + t, 0, gh, mat),
            box(f"goal_{name}_north", s * hl, s * (hl + gd + t), gw, gw + t, 0, gh, mat),
            box(f"goal_{name}_south", s * hl, s * (hl + gd + t), -gw - t, -gw, 0, gh, mat),
            box(f"goal_{name}_crossbar", s * hl, s * (hl + t), -gw, gw, gh - t, gh, mat),
        ]
    return out


def posts():
    hl, hw, band = LENGTH / 2, WIDTH / 2, POST_HEIGHT / 3
    out = []
    for x, xn in ((hl, "east"), (0.0, "mid"), (-hl, "west")):
        for y, yn in ((hw, "north"), (-hw, "south")):
            outer, inner = ("goal_yellow", "goal_blue") if x >= 0 else ("goal_blue", "goal_yellow")
            for k, mat in enumerate((outer, inner, outer)):
                out.append(f'<geom name="post_{xn}_{yn}_{k}" type="cylinder" '
                           f'pos="{f(x, y, band * (k + 0.5))}" size="{f(POST_RADIUS, band / 2)}" '
                           f'material="{mat}"/>')
    return out


def robot(name, marker, k):
    lo, hi = BAND
    parts = [(0.0, lo, "robot"), (lo, hi, marker), (hi, ROBOT_HEIGHT, "robot")]
    geoms = [f'  <geom name="{name}_{i}" type="cylinder" pos="0 0 {f((a + b) / 2)}" '
             f'size="{f(ROBOT_RADIUS, (b - a) / 2)}" material="{mat}"/>'
             for i, (a, b, mat) in enumerate(parts)]
    return ([f'<body name="{name}" mocap="true" pos="{f(2.0 * k, 0, PARKED_Z)}">'] + geoms
            + ["</body>"])


def scene(robots_per_team):
    hx, hy = LENGTH / 2 + BORDER, WIDTH / 2 + BORDER
    q = look_quat(0.0, math.radians(CAMERA_TILT_DEG))
    lines = [
        '<mujoco model="msl_field">',
        "<!-- Generated by make_scene.py (edit the numbers there, or this file by hand).",
        "     MRT's Middle Size League field: metres, z up, origin at the centre spot, +x towards",
        "     the east (yellow) goal, +y towards the north side line. No lights: scenes/*.xml",
        "     include this file and add them. -->",
        '<statistic center="0 0 0.5" extent="12"/>',
        "<visual>",
        '  <map znear="0.005" zfar="3"/>',  # times the extent: 6 cm to 36 m
        f'  <global offwidth="1280" offheight="960" fovy="{f(CAMERA_FOVY_DEG)}"/>',
        "</visual>",
        "<asset>",
        f'  <texture name="hall" type="skybox" builtin="flat" rgb1="{rgb(HALL)}" '
        f'rgb2="{rgb(HALL)}" width="16" height="16"/>',
    ]
    lines.append(circle_mesh())
    for name, (colour, spec, shine) in MATERIALS.items():
        lines.append(f'  <material name="{name}" rgba="{rgba(colour)}" specular="{f(spec)}" '
                     f'shininess="{f(shine)}" reflectance="0"/>')
    lines += ["</asset>", "<worldbody>"]
    body = [f'<geom name="carpet" type="plane" size="{f(hx, hy, 0.1)}" material="carpet"/>']
    body += walls() + field_lines() + goals() + posts()
    body += [
        f'<body name="ball" pos="{f(0, 0, BALL_RADIUS)}">',
        '  <freejoint name="ball"/>',
        f'  <geom name="ball" type="sphere" size="{f(BALL_RADIUS)}" mass="{f(BALL_MASS)}" '
        'material="ball"/>',
        "</body>",
        f'<body name="viewer" mocap="true" pos="{f(*VIEWER_AT, CAMERA_HEIGHT)}" quat="{f(*q)}">',
        f'  <camera name="eye" fovy="{f(CAMERA_FOVY_DEG)}"/>',
        "</body>",
    ]
    for team, marker in (("home", "marker_home"), ("away", "marker_away")):
        for k in range(robots_per_team):
            body += robot(f"{team}{k}", marker, k + (0 if team == "home" else robots_per_team))
    lines += ["  " + b for b in body]
    lines += ["</worldbody>", "</mujoco>", ""]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path(__file__).with_name("field.xml"))
    ap.add_argument("--robots", type=int, default=ROBOTS_PER_TEAM,
                    help="robot bodies a team (home0.., away0..), default %(default)s")
    args = ap.parse_args()
    args.out.write_text(scene(args.robots))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
