"""The exceptions janus2d raises. Each carries ``kind``: the Rust error's
variant (``"StaleBody"``, ``"NonFinite"``, ``"Checksum"``, ...); errors from
a ``WorldBatch`` also carry ``world``, the index of the world at fault."""


class Janus2dError(Exception):
    """Base class of every janus2d error."""

    kind = None
    world = None


class StaleHandleError(Janus2dError, LookupError):
    """A handle whose body, shape, joint or portal pair was destroyed."""


class ForeignHandleError(Janus2dError, ValueError):
    """A handle another world issued."""


class InvalidInputError(Janus2dError, ValueError):
    """A value the engine refuses: non-finite, out of range, a degenerate
    shape, a bad joint or portal definition, a bad time step or query."""


class WrongJointKindError(Janus2dError, TypeError):
    """A joint call that the joint's kind does not have."""


class BodyTypeError(Janus2dError, TypeError):
    """An operation that needs a dynamic (or a movable) body."""


class PortalBodyError(Janus2dError):
    """An operation on a body that carries or is crossing a portal."""


class SnapshotError(Janus2dError, ValueError):
    """Bytes that are not a snapshot this build can restore."""


class BatchError(Janus2dError, ValueError):
    """A batch call with a bad world index, array length or thread count."""


__all__ = [
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
