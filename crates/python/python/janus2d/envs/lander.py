"""LunarLander on janus2d: the rules of Gymnasium's ``LunarLander-v3``
(observation and action spaces, reward terms, termination) on janus2d
bodies, a revolute joint per leg with a motor as its spring.

Units follow the Gymnasium environment: a 20 x 13.3 m viewport (600 x 400
pixels at 30 px/m), 50 steps per second, gravity -10 m/s^2.

The environment's step runs in Rust (:class:`janus2d.LanderBatch`, crate
``janus2d-batch``'s ``lander`` module): :class:`LunarLander` is a thin
Gymnasium wrapper around a one-lander batch, one Rust call per step.

``LanderSim`` is the same rules written with NumPy over a
:class:`janus2d.WorldBatch`, the implementation before the Rust one; it
stays as the reference the tests compare the Rust step with.
"""

from __future__ import annotations

import math

import numpy as np

import janus2d

FPS = 50
PX = 30.0  # pixels per metre of the viewport
VIEW_W = 600 / PX
VIEW_H = 400 / PX
MAIN_POWER = 13.0
SIDE_POWER = 0.6
START_PUSH = 1000.0  # largest initial force component, N
HULL = [(-14, 17), (-17, 0), (-17, -10), (17, -10), (17, 0), (14, 17)]  # px
LEG_OUT = 20  # px, sideways from the hull's centre to the leg
LEG_DROP = 18  # px, down from the hull's centre to the leg
LEG_HALF_W, LEG_HALF_H = 2, 8  # px
LEG_TORQUE = 40.0
SIDE_UP = 14  # px, height of the side thrusters
SIDE_OUT = 12  # px, side thrusters' distance from the centre
MAIN_DOWN = 4  # px, main engine below the centre
CHUNKS = 11
PAD_Y = VIEW_H / 4

# Contact categories: the hull and legs meet only the ground.
GROUND_BITS = 0x0001
HULL_BITS = 0x0010
LEG_BITS = 0x0020

OBS_LOW = np.array([-2.5, -2.5, -10.0, -10.0, -2 * math.pi, -10.0, 0.0, 0.0], dtype=np.float32)
OBS_HIGH = -OBS_LOW
OBS_HIGH[6:] = 1.0


def terrain(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Ground points: random heights, the middle three chunks flat at the
    pad's height, each height averaged with its neighbours."""
    heights = rng.uniform(0.0, VIEW_H / 2, size=CHUNKS + 1)
    xs = np.array([VIEW_W / (CHUNKS - 1) * i for i in range(CHUNKS)])
    mid = CHUNKS // 2
    heights[mid - 2 : mid + 3] = PAD_Y
    smooth = np.array(
        [(heights[i - 1] + heights[i] + heights[i + 1]) / 3.0 for i in range(CHUNKS)]
    )
    return xs, smooth


class Handles:
    """The bodies and joints of one lander world (the same in every world
    built by :func:`build_world`)."""

    def __init__(self, ground, hull, legs, joints, pad_x):
        self.ground = ground
        self.hull = hull
        self.legs = legs
        self.joints = joints
        self.pad_x = pad_x  # (left, right)
        self.bodies = [hull, legs[0], legs[1]]


def build_world(rng: np.random.Generator, gravity: float = -10.0, portal: bool = False):
    """A lander world with random ground; returns ``(world, handles)``.

    Bodies are created in the same order whatever the terrain, so the
    handles of one build address any other build in a WorldBatch.
    """
    world = janus2d.World(gravity=(0.0, gravity))
    xs, ys = terrain(rng)
    ground = world.create_body("static", (0.0, 0.0))
    for i in range(CHUNKS - 1):
        world.create_segment(
            ground,
            (xs[i], ys[i]),
            (xs[i + 1], ys[i + 1]),
            friction=0.1,
            category_bits=GROUND_BITS,
        )
    mid = CHUNKS // 2
    pad_x = (xs[mid - 1], xs[mid + 1])
    if portal:
        from .portal_lander import add_portal_scenery

        add_portal_scenery(world, ground, pad_x)

    x0, y0 = VIEW_W / 2, VIEW_H
    hull = world.create_body("dynamic", (x0, y0))
    world.create_polygon(
        hull,
        [(x / PX, y / PX) for x, y in HULL],
        density=5.0,
        friction=0.1,
        restitution=0.0,
        category_bits=HULL_BITS,
        mask_bits=GROUND_BITS,
    )
    legs, joints = [], []
    for side in (-1, +1):
        # The leg hangs where its joint holds it: the pin is at the hull's
        # centre, the leg's centre LEG_OUT to the side and LEG_DROP below.
        lx, ly = x0 - side * LEG_OUT / PX, y0 - LEG_DROP / PX
        leg = world.create_body("dynamic", (lx, ly))
        world.create_box(
            leg,
            LEG_HALF_W / PX,
            LEG_HALF_H / PX,
            density=1.0,
            restitution=0.0,
            category_bits=LEG_BITS,
            mask_bits=GROUND_BITS,
        )
        # Limits as Gymnasium's: each leg swings out between 0.4 and 0.9 rad;
        # the motor, pushing toward the inner limit, is the leg's spring.
        lower, upper = (0.4, 0.9) if side == -1 else (-0.9, -0.4)
        joint = world.create_revolute_joint(
            hull,
            leg,
            (x0, y0),
            enable_motor=True,
            motor_speed=0.3 * side,
            max_motor_torque=LEG_TORQUE,
            enable_limit=True,
            lower_angle=lower,
            upper_angle=upper,
        )
        legs.append(leg)
        joints.append(joint)
    return world, Handles(ground, hull, legs, joints, pad_x)


def engine_impulses(actions: np.ndarray, angles: np.ndarray, centres: np.ndarray,
                    rng: np.random.Generator, continuous: bool):
    """The main and side engines' impulses for N landers.

    Returns ``(main, side, m_power, s_power)``: two ``(N, 1, 4)`` arrays of
    ``ix, iy, px, py`` (an impulse at a world point) and the throttles
    that the fuel terms of the reward charge.
    """
    n = len(angles)
    up = np.stack([-np.sin(angles), np.cos(angles)], axis=1)  # the hull's up axis
    right = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    jitter = rng.uniform(-1.0, 1.0, size=(n, 2)) / PX
    if continuous:
        a = np.clip(np.asarray(actions, dtype=np.float64).reshape(n, 2), -1.0, 1.0)
        m_power = np.where(a[:, 0] > 0.0, (np.clip(a[:, 0], 0.0, 1.0) + 1.0) * 0.5, 0.0)
        side_dir = np.sign(a[:, 1]) * (np.abs(a[:, 1]) > 0.5)
        s_power = np.where(side_dir != 0, np.clip(np.abs(a[:, 1]), 0.5, 1.0), 0.0)
    else:
        a = np.asarray(actions).reshape(n)
        m_power = (a == 2).astype(np.float64)
        side_dir = np.where(a == 1, -1.0, np.where(a == 3, 1.0, 0.0))
        s_power = (side_dir != 0).astype(np.float64)

    # Main engine: thrust along the hull's up axis, a little off its line
    # (the jitter), from a point below the centre.
    lever = (MAIN_DOWN / PX + 2.0 * jitter[:, :1]) * up + jitter[:, 1:] * right
    main = np.zeros((n, 1, 4))
    main[:, 0, 0:2] = lever * (MAIN_POWER * m_power)[:, None]
    main[:, 0, 2:4] = centres - lever

    # Side engine: a sideways push high on the hull, so it also turns it:
    # as in Gymnasium, action 1 (the left engine) pushes left from the
    # right of the centre (turning the lander counterclockwise), action 3
    # the mirror image.
    offset = -side_dir * (SIDE_OUT / PX) + 3.0 * jitter[:, 1]
    side = np.zeros((n, 1, 4))
    side[:, 0, 0:2] = (right * offset[:, None] + jitter[:, :1] * up) * (-SIDE_POWER * s_power)[:, None]
    side[:, 0, 2:4] = centres + right * offset[:, None] + up * (SIDE_UP / PX)
    return main, side, m_power, s_power


class LanderSim:
    """N landers in a WorldBatch, with Gymnasium's observation and reward,
    in NumPy (the reference for :class:`janus2d.LanderBatch`)."""

    def __init__(self, n: int, rng: np.random.Generator, continuous=False, gravity=-10.0,
                 threads=1, portal=False):
        self.n = n
        self.continuous = continuous
        self.gravity = gravity
        self.portal = portal
        self.rng = rng
        world, self.h = build_world(rng, gravity, portal)
        self.pads = np.zeros((n, 2))
        self.batch = janus2d.WorldBatch(world, n, threads=threads)
        self.prev_shaping = np.full(n, np.nan)

    def reset(self, mask: np.ndarray, rng: np.random.Generator | None = None) -> None:
        """New terrain and a random push for the landers in ``mask``."""
        rng = self.rng if rng is None else rng
        for i in np.flatnonzero(mask):
            world, h = build_world(rng, self.gravity, self.portal)
            self.pads[i] = h.pad_x
            self.batch.set_world(int(i), world)
        push = np.zeros((self.n, 1, 3))
        k = int(np.count_nonzero(mask))
        push[mask, 0, 0:2] = rng.uniform(-START_PUSH, START_PUSH, size=(k, 2))
        self.batch.apply_forces([self.h.hull], push)
        self.prev_shaping[mask] = np.nan

    def observe(self):
        """``(obs, hull_contacts, awake)`` for every lander."""
        s = self.batch.get_state(self.h.bodies)
        contacts = self.batch.get_contact_counts(self.h.bodies)
        awake = self.batch.get_awake([self.h.hull])[:, 0]
        hull = s[:, 0]
        obs = np.empty((self.n, 8), dtype=np.float32)
        obs[:, 0] = (hull[:, 0] - VIEW_W / 2) / (VIEW_W / 2)
        obs[:, 1] = (hull[:, 1] - (PAD_Y + LEG_DROP / PX)) / (VIEW_H / 2)
        obs[:, 2] = hull[:, 3] * (VIEW_W / 2) / FPS
        obs[:, 3] = hull[:, 4] * (VIEW_H / 2) / FPS
        obs[:, 4] = hull[:, 2]
        obs[:, 5] = 20.0 * hull[:, 5] / FPS
        obs[:, 6] = contacts[:, 1] > 0
        obs[:, 7] = contacts[:, 2] > 0
        return obs, contacts[:, 0] > 0, awake

    def shaping(self, obs: np.ndarray) -> np.ndarray:
        """Gymnasium's potential: distance to the pad, speed and tilt cost,
        10 points a leg on the ground."""
        return (
            -100.0 * np.hypot(obs[:, 0], obs[:, 1])
            - 100.0 * np.hypot(obs[:, 2], obs[:, 3])
            - 100.0 * np.abs(obs[:, 4])
            + 10.0 * obs[:, 6]
            + 10.0 * obs[:, 7]
        )

    def step(self, actions, fresh: np.ndarray | None = None):
        """One step of every lander: ``(obs, reward, terminated)``.

        Landers in ``fresh`` were just reset: their engines stay off, the
        step applies their initial push, and the observation after it is
        their first (reward 0), as Gymnasium's reset takes one step.
        """
        actions = np.array(actions, copy=True)
        if fresh is not None and fresh.any():
            if self.continuous:
                actions = actions.reshape(self.n, 2)
                actions[fresh] = (-1.0, 0.0)
            else:
                actions = actions.reshape(self.n)
                actions[fresh] = 0
        s = self.batch.get_state([self.h.hull])
        angles = s[:, 0, 2]
        centres = s[:, 0, 0:2]
        main, side, m_power, s_power = engine_impulses(
            actions, angles, centres, self.rng, self.continuous
        )
        self.batch.apply_impulses([self.h.hull], main)
        self.batch.apply_impulses([self.h.hull], side)
        self.batch.step(1.0 / FPS)
        obs, crashed, awake = self.observe()
        shaping = self.shaping(obs)
        reward = shaping - self.prev_shaping
        self.prev_shaping = shaping
        reward -= 0.30 * m_power
        reward -= 0.03 * s_power
        out = crashed | (np.abs(obs[:, 0]) >= 1.0)
        rest = ~awake & ~out
        reward = np.where(out, -100.0, reward)
        reward = np.where(rest, 100.0, reward)
        done = out | rest
        if fresh is not None:
            reward = np.where(fresh, 0.0, reward)
            done = done & ~fresh
        return obs, reward, done

    def render(self, index: int = 0) -> np.ndarray:
        """An RGB frame of lander ``index``: (400, 600, 3) uint8."""
        return self.batch.world(index).render(
            600, 400, center=(VIEW_W / 2, VIEW_H / 2), scale=PX
        )


class LunarLander:
    """Placeholder replaced below once gymnasium is imported."""


def wind_warnings(wind_power: float, turbulence_power: float) -> None:
    """Gymnasium's warnings for wind powers outside the recommended
    ranges (0 to 20 N, 0 to 2 N·m); non-finite ones are refused by Rust."""
    import warnings

    if not 0.0 <= wind_power <= 20.0:
        warnings.warn(
            f"wind_power value is recommended to be between 0.0 and 20.0, "
            f"(current value: {wind_power})", stacklevel=3)
    if not 0.0 <= turbulence_power <= 2.0:
        warnings.warn(
            f"turbulence_power value is recommended to be between 0.0 and 2.0, "
            f"(current value: {turbulence_power})", stacklevel=3)


try:
    import gymnasium as gym
    from gymnasium import spaces
except ImportError:  # pragma: no cover - gymnasium is optional
    gym = None

if gym is not None:

    class LunarLander(gym.Env):  # noqa: F811
        """Gymnasium's LunarLander on janus2d (``janus2d/LunarLander-v0``).

        ``continuous=False``: ``Discrete(4)`` (nothing, left engine, main
        engine, right engine); ``True``: ``Box(-1, 1, (2,))`` (main
        throttle, side throttle). Observation: the 8 values of Gymnasium's
        environment, in its bounds. ``portal=True`` is the portal variant.
        ``enable_wind``, ``wind_power`` (N) and ``turbulence_power`` (N·m)
        are Gymnasium's: while neither leg is down, a sideways force and a
        torque, ``tanh(sin(0.02 t) + sin(0.01 pi t))`` times the power,
        each count ``t`` starting at a random integer at the reset.
        Each step is one call into Rust (:class:`janus2d.LanderBatch` of
        one lander); an action outside the space raises
        :class:`janus2d.errors.InvalidInputError` (a ``ValueError``).
        """

        metadata = {"render_modes": ["rgb_array"], "render_fps": FPS}

        def __init__(self, render_mode=None, continuous=False, gravity=-10.0, portal=False,
                     enable_wind=False, wind_power=15.0, turbulence_power=1.5):
            if not -12.0 < gravity < 0.0:
                raise ValueError(f"gravity {gravity}: between -12 and 0 (exclusive)")
            wind_warnings(wind_power, turbulence_power)
            if render_mode not in (None, "rgb_array"):
                raise ValueError(f"render_mode {render_mode!r}: None or 'rgb_array'")
            self.render_mode = render_mode
            self.continuous = continuous
            self.gravity = gravity
            self.portal = portal
            self.enable_wind = enable_wind
            self.wind_power = wind_power
            self.turbulence_power = turbulence_power
            self.observation_space = spaces.Box(OBS_LOW, OBS_HIGH, dtype=np.float32)
            if continuous:
                self.action_space = spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
            else:
                self.action_space = spaces.Discrete(4)
            self.core = None

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            # The lander's own generator (terrain, push, engine dispersion)
            # is seeded from the environment's, so `seed` decides it all.
            core_seed = int(self.np_random.integers(0, 2**63))
            if self.core is None:
                self.core = janus2d.LanderBatch(
                    1, continuous=self.continuous, gravity=self.gravity,
                    portal=self.portal, seed=core_seed, enable_wind=self.enable_wind,
                    wind_power=self.wind_power, turbulence_power=self.turbulence_power,
                )
            obs = self.core.reset(core_seed)
            return obs[0], {}

        def step(self, action):
            core = self.core
            if core is None:
                raise RuntimeError("call reset() before step()")
            obs, reward, terminated = core.step_one(action)
            return obs, reward, terminated, False, {}

        def render(self):
            if self.render_mode is None:
                gym.logger.warn("render() without render_mode: pass render_mode='rgb_array'")
                return None
            if self.core is None:
                raise RuntimeError("call reset() before render()")
            return self.core.world(0).render(
                600, 400, center=(VIEW_W / 2, VIEW_H / 2), scale=PX
            )

        def close(self):
            self.core = None
