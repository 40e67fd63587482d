"""mrt_world: the Python side of MRT's device protocol (docs/devices.md) for worlds.

A world (a simulator, or the bridge to a real robot) opens a :class:`World`, waits for its
robots, then sends each step's :func:`sense` and gets each robot's act back.
"""

from .protocol import (
    MAX_MESSAGE,
    PROTOCOL,
    ProtocolError,
    act_key,
    alive_key,
    bye_key,
    camera,
    check_name,
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
from .world import HOLD, Command, World

__all__ = [
    "HOLD",
    "MAX_MESSAGE",
    "PROTOCOL",
    "Command",
    "ProtocolError",
    "World",
    "act_key",
    "alive_key",
    "bye_key",
    "camera",
    "check_name",
    "encode",
    "end_key",
    "game",
    "jpeg_image",
    "odometry",
    "parse_act",
    "parse_bye",
    "pose",
    "rgb8_image",
    "seen",
    "sense",
    "sense_key",
    "sonar",
]
