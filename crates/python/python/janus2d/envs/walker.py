"""BipedalWalker on janus2d: the rules of Gymnasium's ``BipedalWalker-v3``
(normal terrain): 24 observations (hull, four joints, two feet, ten lidar
fractions), four motor actions in [-1, 1], reward for forward progress,
-100 for a fall. Each leg is two boxes on revolute joints whose motors
the actions drive (speed from the sign, torque from the magnitude).

``WalkerSim`` holds N walkers in a :class:`janus2d.WorldBatch`; the single
environment uses N = 1, :class:`BipedalWalkerVector` N > 1.
"""

from __future__ import annotations

import math

import numpy as np

import janus2d

FPS = 50
PX = 30.0
VIEW_W = 600 / PX
VIEW_H = 400 / PX
MOTOR_TORQUE = 80.0
HIP_SPEED = 4.0
KNEE_SPEED = 6.0
LIDAR_RANGE = 160 / PX
START_PUSH = 5.0
HULL = [(-30, 9), (6, 9), (34, 1), (34, -8), (-30, -8)]  # px
HIP_DROP = 8 / PX  # the hips are this far below the hull's centre
LEG_W = 8 / PX
LEG_H = 34 / PX
STEP = 14 / PX  # terrain step, m
TERRAIN_STEPS = 200
TERRAIN_H = VIEW_H / 4
GRASS = 10
START_PAD = 20
GROUND_FRICTION = 2.5
GROUND_BITS = 0x0001
WALKER_BITS = 0x0020

OBS_HIGH = np.array(
    [math.pi, 5, 5, 5, math.pi, 5, math.pi, 5, 5, math.pi, 5, math.pi, 5, 5] + [1.0] * 10,
    dtype=np.float32,
)
OBS_LOW = -OBS_HIGH
OBS_LOW[8] = 0.0
OBS_LOW[13] = 0.0


def terrain(rng: np.random.Generator) -> np.ndarray:
    """Ground heights: flat for the start pad, then a damped random walk
    about the terrain height (the normal, not the hardcore, course)."""
    y = TERRAIN_H
    velocity = 0.0
    ys = np.empty(TERRAIN_STEPS)
    for i in range(TERRAIN_STEPS):
        velocity = 0.8 * velocity + 0.01 * math.copysign(1.0, TERRAIN_H - y)
        if i > START_PAD:
            velocity += rng.uniform(-1.0, 1.0) / PX
        y += velocity
        ys[i] = y
    return ys


def hardcore_terrain(rng: np.random.Generator):
    """Gymnasium's hardcore course: grass stretches (the damped random walk)
    alternating with an obstacle drawn at random: a pit (3 or 4 steps wide,
    4 deep, walls 1 step thick), a stump (a square 1 or 2 steps wide) or
    stairs (3 or 4 steps of 4 steps' width, 1 step up or down each).
    Returns ``(heights, polygons)``: the ground's heights (into the pits)
    and the obstacles' outlines, m."""
    grass, stump, stairs, pit = range(4)
    state, velocity, y = grass, 0.0, TERRAIN_H
    counter, oneshot = START_PAD, False
    stair_steps = stair_width = stair_height = 0
    base_y = 0.0
    ys = np.empty(TERRAIN_STEPS)
    polygons = []

    def box(x0, y0, x1, y1):
        return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]

    for i in range(TERRAIN_STEPS):
        x = i * STEP
        if state == grass and not oneshot:
            velocity = 0.8 * velocity + 0.01 * np.sign(TERRAIN_H - y)
            if i > START_PAD:
                velocity += rng.uniform(-1.0, 1.0) / PX
            y += velocity
        elif state == pit and oneshot:
            counter = int(rng.integers(3, 5))
            wall = box(x, y - 4 * STEP, x + STEP, y)
            polygons.append(wall)
            polygons.append([(px + STEP * counter, py) for px, py in wall])
            counter += 2
            base_y = y
        elif state == pit and not oneshot:
            y = base_y
            if counter > 1:
                y -= 4 * STEP
        elif state == stump and oneshot:
            counter = int(rng.integers(1, 3))
            polygons.append(box(x, y, x + counter * STEP, y + counter * STEP))
        elif state == stairs and oneshot:
            stair_height = 1 if rng.random() > 0.5 else -1
            stair_width = int(rng.integers(4, 5))
            stair_steps = int(rng.integers(3, 5))
            base_y = y
            for k in range(stair_steps):
                polygons.append(box(
                    x + k * stair_width * STEP, y + (k * stair_height - 1) * STEP,
                    x + (k + 1) * stair_width * STEP, y + k * stair_height * STEP,
                ))
            counter = stair_steps * stair_width
        elif state == stairs and not oneshot:
            done = stair_steps * stair_width - counter - stair_height
            y = base_y + done / stair_width * stair_height * STEP
        oneshot = False
        ys[i] = y
        counter -= 1
        if counter == 0:
            counter = int(rng.integers(GRASS // 2, GRASS))
            state = int(rng.integers(1, 4)) if state == grass else grass
            oneshot = True
    return ys, polygons


class WalkerHandles:
    """The bodies and joints of one walker world."""

    def __init__(self, hull, uppers, lowers, joints):
        self.hull = hull
        self.uppers = uppers
        self.lowers = lowers
        self.joints = joints  # hip 0, knee 0, hip 1, knee 1
        self.bodies = [hull, lowers[0], lowers[1]]


def build_world(rng: np.random.Generator, hardcore: bool = False):
    """A walker on new random terrain (``hardcore``: Gymnasium's course
    with pits, stumps and stairs): ``(world, handles)``; the bodies and
    joints are created in the same order in every build, so their handles
    carry over (the obstacles are shapes of the ground body)."""
    world = janus2d.World(gravity=(0.0, -10.0))
    ys, polygons = hardcore_terrain(rng) if hardcore else (terrain(rng), [])
    ground = world.create_body("static", (0.0, 0.0))
    for poly in polygons:
        world.create_polygon(ground, poly, friction=GROUND_FRICTION, category_bits=GROUND_BITS)
    for i in range(TERRAIN_STEPS - 1):
        world.create_segment(
            ground,
            (i * STEP, ys[i]),
            ((i + 1) * STEP, ys[i + 1]),
            friction=GROUND_FRICTION,
            category_bits=GROUND_BITS,
        )
    x0 = STEP * START_PAD / 2
    y0 = TERRAIN_H + 2 * LEG_H
    hull = world.create_body("dynamic", (x0, y0))
    world.create_polygon(
        hull,
        [(x / PX, y / PX) for x, y in HULL],
        density=5.0,
        friction=0.1,
        category_bits=WALKER_BITS,
        mask_bits=GROUND_BITS,
    )
    hip_y = y0 - HIP_DROP
    uppers, lowers, joints = [], [], []
    for side in (-1, +1):
        upper = world.create_body("dynamic", (x0, hip_y - LEG_H / 2))
        world.create_box(upper, LEG_W / 2, LEG_H / 2, density=1.0, friction=0.2,
                         category_bits=WALKER_BITS, mask_bits=GROUND_BITS)
        hip = world.create_revolute_joint(
            hull, upper, (x0, hip_y),
            enable_motor=True, motor_speed=float(side), max_motor_torque=MOTOR_TORQUE,
            enable_limit=True, lower_angle=-0.8, upper_angle=1.1,
        )
        lower = world.create_body("dynamic", (x0, hip_y - 1.5 * LEG_H))
        world.create_box(lower, 0.8 * LEG_W / 2, LEG_H / 2, density=1.0, friction=0.2,
                         category_bits=WALKER_BITS, mask_bits=GROUND_BITS)
        knee = world.create_revolute_joint(
            upper, lower, (x0, hip_y - LEG_H),
            enable_motor=True, motor_speed=1.0, max_motor_torque=MOTOR_TORQUE,
            enable_limit=True, lower_angle=-1.6, upper_angle=-0.1,
        )
        uppers.append(upper)
        lowers.append(lower)
        joints += [hip, knee]
    return world, WalkerHandles(hull, uppers, lowers, joints)


class WalkerSim:
    """N walkers in a WorldBatch, with Gymnasium's observation and reward."""

    def __init__(self, n: int, rng: np.random.Generator, threads: int = 1,
                 hardcore: bool = False):
        self.n = n
        self.rng = rng
        self.hardcore = hardcore
        world, self.h = build_world(rng, hardcore)
        self.batch = janus2d.WorldBatch(world, n, threads=threads)
        self.prev_shaping = np.full(n, np.nan)
        angles = 1.5 * np.arange(10) / 10.0
        self.lidar_dirs = np.stack([np.sin(angles), -np.cos(angles)], axis=1) * LIDAR_RANGE

    def reset(self, mask: np.ndarray, rng: np.random.Generator | None = None) -> None:
        """New terrain and a random sideways push for the walkers in ``mask``."""
        rng = self.rng if rng is None else rng
        for i in np.flatnonzero(mask):
            world, _ = build_world(rng, self.hardcore)
            self.batch.set_world(int(i), world)
        push = np.zeros((self.n, 1, 3))
        push[mask, 0, 0] = rng.uniform(-START_PUSH, START_PUSH, size=int(mask.sum()))
        self.batch.apply_forces([self.h.hull], push)
        self.prev_shaping[mask] = np.nan

    def observe(self):
        """``(obs, hull_x, hull_down)`` of every walker."""
        s = self.batch.get_state(self.h.bodies)
        joints = self.batch.get_joint_angles(self.h.joints)
        contacts = self.batch.get_contact_counts(self.h.bodies)
        hull = s[:, 0]
        origins = hull[:, None, 0:2].repeat(10, axis=1)
        rays = np.concatenate([origins, np.broadcast_to(self.lidar_dirs, origins.shape)], axis=2)
        lidar = self.batch.cast_rays(rays, mask_bits=GROUND_BITS)
        obs = np.empty((self.n, 24), dtype=np.float32)
        obs[:, 0] = hull[:, 2]
        obs[:, 1] = 2.0 * hull[:, 5] / FPS
        obs[:, 2] = 0.3 * hull[:, 3] * VIEW_W / FPS
        obs[:, 3] = 0.3 * hull[:, 4] * VIEW_H / FPS
        for leg in range(2):
            hip, knee = joints[:, 2 * leg], joints[:, 2 * leg + 1]
            base = 4 + 5 * leg
            obs[:, base] = hip[:, 0]
            obs[:, base + 1] = hip[:, 1] / HIP_SPEED
            obs[:, base + 2] = knee[:, 0] + 1.0
            obs[:, base + 3] = knee[:, 1] / KNEE_SPEED
            obs[:, base + 4] = contacts[:, 1 + leg] > 0
        obs[:, 14:] = lidar
        return obs, hull[:, 0], contacts[:, 0] > 0

    def step(self, actions, fresh: np.ndarray | None = None):
        """One step of every walker: ``(obs, reward, terminated)``. Walkers
        in ``fresh`` were just reset: motors idle, reward 0."""
        a = np.clip(np.asarray(actions, dtype=np.float64).reshape(self.n, 4), -1.0, 1.0)
        if fresh is not None:
            a[fresh] = 0.0
        top = np.array([HIP_SPEED, KNEE_SPEED, HIP_SPEED, KNEE_SPEED])
        self.batch.set_motor_speeds(self.h.joints, top * np.sign(a))
        self.batch.set_max_motor_torques(self.h.joints, MOTOR_TORQUE * np.abs(a))
        self.batch.step(1.0 / FPS)
        obs, x, fallen = self.observe()
        shaping = 130.0 * x / PX - 5.0 * np.abs(obs[:, 0])
        reward = shaping - self.prev_shaping
        self.prev_shaping = shaping
        reward -= 0.00035 * MOTOR_TORQUE * np.abs(a).sum(axis=1)
        lost = fallen | (x < 0.0)
        reward = np.where(lost, -100.0, reward)
        done = lost | (x > (TERRAIN_STEPS - GRASS) * STEP)
        if fresh is not None:
            reward = np.where(fresh, 0.0, reward)
            done = done & ~fresh
        return obs, reward, done

    def render(self, index: int = 0) -> np.ndarray:
        """An RGB frame following walker ``index``: (400, 600, 3) uint8."""
        x = float(self.batch.get_state([self.h.hull])[index, 0, 0])
        world = self.batch.world(index)
        return world.render(600, 400, center=(x + VIEW_W / 4, TERRAIN_H + 2.0), scale=PX)


try:
    import gymnasium as gym
    from gymnasium import spaces
    from gymnasium.vector import AutoresetMode, VectorEnv
    from gymnasium.vector.utils import batch_space
except ImportError:  # pragma: no cover - gymnasium is optional
    gym = None

if gym is not None:

    class BipedalWalker(gym.Env):
        """Gymnasium's BipedalWalker on janus2d (``janus2d/BipedalWalker-v0``;
        ``hardcore=True``, ``janus2d/BipedalWalkerHardcore-v0``: the course
        with pits, stumps and stairs)."""

        metadata = {"render_modes": ["rgb_array"], "render_fps": FPS}

        def __init__(self, render_mode=None, hardcore=False):
            self.hardcore = bool(hardcore)
            if render_mode not in (None, "rgb_array"):
                raise ValueError(f"render_mode {render_mode!r}: None or 'rgb_array'")
            self.render_mode = render_mode
            self.observation_space = spaces.Box(OBS_LOW, OBS_HIGH, dtype=np.float32)
            self.action_space = spaces.Box(-1.0, 1.0, (4,), dtype=np.float32)
            self.sim = None

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            if self.sim is None or seed is not None:
                self.sim = WalkerSim(1, self.np_random, hardcore=self.hardcore)
            self.sim.rng = self.np_random
            fresh = np.ones(1, dtype=bool)
            self.sim.reset(fresh)
            obs, _, _ = self.sim.step(np.zeros((1, 4)), fresh)
            return obs[0], {}

        def step(self, action):
            if self.sim is None:
                raise RuntimeError("call reset() before step()")
            action = np.asarray(action, dtype=np.float64)
            if action.shape != (4,) or not np.all(np.isfinite(action)):
                raise ValueError(f"action {action!r}: 4 finite values in [-1, 1]")
            obs, reward, done = self.sim.step(action[None, :])
            return obs[0], float(reward[0]), bool(done[0]), False, {}

        def render(self):
            if self.render_mode is None:
                gym.logger.warn("render() without render_mode: pass render_mode='rgb_array'")
                return None
            if self.sim is None:
                raise RuntimeError("call reset() before render()")
            return self.sim.render(0)

        def close(self):
            self.sim = None

    class BipedalWalkerVector(VectorEnv):
        """``num_envs`` walkers in one WorldBatch (next-step autoreset)."""

        metadata = {
            "render_modes": ["rgb_array"],
            "render_fps": FPS,
            "autoreset_mode": AutoresetMode.NEXT_STEP,
        }

        def __init__(self, num_envs: int, threads: int = 1, max_episode_steps=None,
                     render_mode=None, hardcore: bool = False):
            if max_episode_steps is None:
                max_episode_steps = 2000 if hardcore else 1600
            self.hardcore = hardcore
            self.num_envs = num_envs
            self.threads = threads
            self.max_episode_steps = max_episode_steps
            self.render_mode = render_mode
            self.single_observation_space = spaces.Box(OBS_LOW, OBS_HIGH, dtype=np.float32)
            self.single_action_space = spaces.Box(-1.0, 1.0, (4,), dtype=np.float32)
            self.observation_space = batch_space(self.single_observation_space, num_envs)
            self.action_space = batch_space(self.single_action_space, num_envs)
            self.sim = None
            self._rng = np.random.default_rng()
            self._autoreset = np.zeros(num_envs, dtype=bool)
            self._steps = np.zeros(num_envs, dtype=np.int64)

        def reset(self, *, seed=None, options=None):
            if seed is not None:
                self._rng = np.random.default_rng(seed)
            if self.sim is None or seed is not None:
                self.sim = WalkerSim(self.num_envs, self._rng, threads=self.threads,
                                     hardcore=self.hardcore)
            mask = np.ones(self.num_envs, dtype=bool)
            self.sim.reset(mask, self._rng)
            obs, _, _ = self.sim.step(np.zeros((self.num_envs, 4)), mask)
            self._autoreset[:] = False
            self._steps[:] = 0
            return obs, {}

        def step(self, actions):
            fresh = self._autoreset.copy()
            if fresh.any():
                self.sim.reset(fresh, self._rng)
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
else:  # pragma: no cover
    BipedalWalker = None
    BipedalWalkerVector = None
