"""A vector LunarLander over one :class:`janus2d.LanderBatch`: N landers
stepped in one Rust call on the batch's threads (engines, world steps,
observations, rewards, autoresets), the GIL released, the results as
arrays.

It follows Gymnasium's ``VectorEnv`` interface with next-step autoreset:
the step after an episode ends resets that lander (its action is ignored,
its reward is 0) and returns its first observation.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

import janus2d

from .lander import FPS, OBS_HIGH, OBS_LOW, PX, VIEW_H, VIEW_W, wind_warnings


class LunarLanderVector(VectorEnv):
    """``num_envs`` landers in a LanderBatch of ``threads`` threads."""

    metadata = {
        "render_modes": ["rgb_array"],
        "render_fps": FPS,
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }

    def __init__(self, num_envs: int, threads: int = 1, continuous: bool = False,
                 gravity: float = -10.0, max_episode_steps: int = 1000,
                 render_mode=None, portal: bool = False, enable_wind: bool = False,
                 wind_power: float = 15.0, turbulence_power: float = 1.5):
        wind_warnings(wind_power, turbulence_power)
        self.num_envs = num_envs
        self.continuous = continuous
        self.gravity = gravity
        self.threads = threads
        self.portal = portal
        self.enable_wind = enable_wind
        self.wind_power = wind_power
        self.turbulence_power = turbulence_power
        self.render_mode = render_mode
        self.max_episode_steps = max_episode_steps
        self.single_observation_space = spaces.Box(OBS_LOW, OBS_HIGH, dtype=np.float32)
        if continuous:
            self.single_action_space = spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
        else:
            self.single_action_space = spaces.Discrete(4)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.core = None
        self._rng = np.random.default_rng()

    def reset(self, *, seed=None, options=None):
        if seed is not None:
            self._rng = np.random.default_rng(seed)
        core_seed = int(self._rng.integers(0, 2**63))
        if self.core is None:
            self.core = janus2d.LanderBatch(
                self.num_envs, threads=self.threads, continuous=self.continuous,
                gravity=self.gravity, portal=self.portal,
                max_episode_steps=self.max_episode_steps, autoreset=True, seed=core_seed,
                enable_wind=self.enable_wind, wind_power=self.wind_power,
                turbulence_power=self.turbulence_power,
            )
        return self.core.reset(core_seed), {}

    def step(self, actions):
        if self.core is None:
            raise RuntimeError("call reset() before step()")
        obs, reward, terminated, truncated = self.core.step(actions)
        return obs, reward, terminated, truncated, {}

    def render(self):
        if self.render_mode != "rgb_array" or self.core is None:
            return None
        return tuple(
            self.core.world(i).render(600, 400, center=(VIEW_W / 2, VIEW_H / 2), scale=PX)
            for i in range(self.num_envs)
        )

    def close_extras(self, **kwargs):
        self.core = None
