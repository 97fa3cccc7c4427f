"""Gymnasium environments on janus2d. Importing this module registers:

- ``janus2d/LunarLander-v0`` (``continuous=True`` for the Box action space),
- ``janus2d/LunarLanderPortal-v0`` (the pad is reached through a portal),
- ``janus2d/BipedalWalker-v0``,
- ``janus2d/BipedalWalkerHardcore-v0`` (``hardcore=True``: pits, stumps, stairs),

with Gymnasium's time limits (1000, 1600 and 2000 steps). The vector
environments over a :class:`janus2d.WorldBatch` are
:class:`LunarLanderVector` and :class:`BipedalWalkerVector`.

``gymnasium.make("janus2d.envs:janus2d/LunarLander-v0")`` imports and
registers in one call.
"""

from .lander import LanderSim, LunarLander
from .vector import LunarLanderVector
from .walker import BipedalWalker, BipedalWalkerVector


def register_envs() -> None:
    """Registers the environments with Gymnasium (idempotent)."""
    from gymnasium.envs.registration import register, registry

    specs = [
        ("janus2d/LunarLander-v0", "janus2d.envs.lander:LunarLander", {}, 1000, 200),
        ("janus2d/LunarLanderPortal-v0", "janus2d.envs.lander:LunarLander",
         {"portal": True}, 1000, 200),
        ("janus2d/BipedalWalker-v0", "janus2d.envs.walker:BipedalWalker", {}, 1600, 300),
        ("janus2d/BipedalWalkerHardcore-v0", "janus2d.envs.walker:BipedalWalker",
         {"hardcore": True}, 2000, 300),
    ]
    for env_id, entry, kwargs, steps, threshold in specs:
        if env_id not in registry:
            register(
                id=env_id,
                entry_point=entry,
                kwargs=kwargs,
                max_episode_steps=steps,
                reward_threshold=threshold,
            )


register_envs()

__all__ = [
    "LunarLander",
    "LunarLanderVector",
    "LanderSim",
    "BipedalWalker",
    "BipedalWalkerVector",
    "register_envs",
]
