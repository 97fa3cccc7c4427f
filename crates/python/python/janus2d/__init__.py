"""janus2d: a 2D rigid-body physics engine with portals, from Python.

>>> import janus2d
>>> world = janus2d.World()
>>> ground = world.create_body("static", (0.0, -0.5))
>>> _ = world.create_box(ground, 10.0, 0.5)
>>> ball = world.create_body("dynamic", (0.0, 2.0))
>>> _ = world.create_circle(ball, 0.5)
>>> world.step(1 / 60, steps=120)
>>> round(world.position(ball)[1], 1)
0.5

Definitions are keyword arguments named as the Rust definition fields;
anything not given keeps the Rust default (``janus2d.defaults(kind)`` lists
them). Rust errors are the exceptions of :mod:`janus2d.errors`. Many worlds
step together in a :class:`WorldBatch`; Gymnasium environments are in
:mod:`janus2d.envs` (``import janus2d.envs`` registers
``janus2d/LunarLander-v0`` and ``janus2d/BipedalWalker-v0``).
"""

from ._janus2d import (
    SNAPSHOT_VERSION,
    Body,
    Joint,
    PortalPair,
    Shape,
    World,
    LanderBatch,
    WorldBatch,
    defaults,
    real_bytes,
)
from .errors import (
    BatchError,
    BodyTypeError,
    ForeignHandleError,
    InvalidInputError,
    Janus2dError,
    PortalBodyError,
    SnapshotError,
    StaleHandleError,
    WrongJointKindError,
)

__version__ = "0.1.0"

__all__ = [
    "World",
    "WorldBatch",
    "LanderBatch",
    "Body",
    "Shape",
    "Joint",
    "PortalPair",
    "defaults",
    "real_bytes",
    "SNAPSHOT_VERSION",
    "Janus2dError",
    "StaleHandleError",
    "ForeignHandleError",
    "InvalidInputError",
    "WrongJointKindError",
    "BodyTypeError",
    "PortalBodyError",
    "SnapshotError",
    "BatchError",
]
