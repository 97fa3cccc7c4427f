"""A vector LunarLander over one :class:`janus2d.WorldBatch`: N landers
stepped in one call on rayon threads, observations and rewards as arrays.

It follows Gymnasium's ``VectorEnv`` interface with next-step autoreset:
the step after an episode ends resets that lander (its action is ignored,
its reward is 0) and returns its first observation.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from .lander import FPS, OBS_HIGH, OBS_LOW, LanderSim


class LunarLanderVector(VectorEnv):
    """``num_envs`` landers in a WorldBatch of ``threads`` threads."""

    metadata = {
        "render_modes": ["rgb_array"],
        "render_fps": FPS,
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }

    def __init__(self, num_envs: int, threads: int = 1, continuous: bool = False,
                 gravity: float = -10.0, max_episode_steps: int = 1000,
                 render_mode=None, portal: bool = False):
        self.num_envs = num_envs
        self.continuous = continuous
        self.gravity = gravity
        self.threads = threads
        self.portal = portal
        self.render_mode = render_mode
        self.max_episode_steps = max_episode_steps
        self.single_observation_space = spaces.Box(OBS_LOW, OBS_HIGH, dtype=np.float32)
        if continuous:
            self.single_action_space = spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
        else:
            self.single_action_space = spaces.Discrete(4)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.sim = None
        self._rng = np.random.default_rng()
        self._autoreset = np.zeros(num_envs, dtype=bool)
        self._steps = np.zeros(num_envs, dtype=np.int64)

    def _noop(self):
        if self.continuous:
            return np.tile(np.array([-1.0, 0.0]), (self.num_envs, 1))
        return np.zeros(self.num_envs, dtype=np.int64)

    def reset(self, *, seed=None, options=None):
        if seed is not None:
            self._rng = np.random.default_rng(seed)
        if self.sim is None or seed is not None:
            self.sim = LanderSim(self.num_envs, self._rng, self.continuous, self.gravity,
                                 threads=self.threads, portal=self.portal)
        mask = np.ones(self.num_envs, dtype=bool)
        self.sim.reset(mask, self._rng)
        obs, _, _ = self.sim.step(self._noop(), mask)
        self._autoreset[:] = False
        self._steps[:] = 0
        return obs, {}

    def step(self, actions):
        fresh = self._autoreset.copy()
        if fresh.any():
            self.sim.reset(fresh, self._rng)
            self._steps[fresh] = 0
        obs, reward, terminated = self.sim.step(actions, fresh)
        self._steps += 1
        self._steps[fresh] = 0
        truncated = (self._steps >= self.max_episode_steps) & ~terminated
        self._autoreset = terminated | truncated
        return obs, reward.astype(np.float64), terminated, truncated, {}

    def render(self):
        if self.render_mode != "rgb_array" or self.sim is None:
            return None
        return tuple(self.sim.render(i) for i in range(self.num_envs))

    def close_extras(self, **kwargs):
        self.sim = None
