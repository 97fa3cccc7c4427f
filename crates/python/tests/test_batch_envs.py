"""WorldBatch (determinism across thread counts, arrays, errors) and the
Gymnasium environments (the checker, episodes, a vectorised rollout)."""

import hashlib

import numpy as np
import pytest

import janus2d
from janus2d import errors

gym = pytest.importorskip("gymnasium")
from gymnasium.utils.env_checker import check_env  # noqa: E402

import janus2d.envs  # noqa: E402,F401  (registers the environments)
from janus2d.envs import BipedalWalkerVector, LunarLanderVector  # noqa: E402

DT = 1.0 / 60.0


def stack_world():
    world = janus2d.World()
    ground = world.create_body("static", (0.0, -0.5))
    world.create_box(ground, 20.0, 0.5)
    boxes = []
    for i in range(4):
        b = world.create_body("dynamic", (0.05 * i, 0.5 + 1.05 * i))
        world.create_box(b, 0.5, 0.5)
        boxes.append(b)
    return world, boxes


def run_batch(threads, n=24, steps=60):
    world, boxes = stack_world()
    batch = janus2d.WorldBatch(world, n, threads=threads)
    v = np.zeros((n, len(boxes), 3))
    v[:, 3, 0] = np.linspace(-3.0, 3.0, n)  # each world's top box pushed differently
    batch.set_velocities(boxes, v)
    batch.step(DT, steps=steps)
    return batch.state_hashes(), batch.get_state(boxes)


def test_batch_same_bits_for_one_and_two_threads():
    h1, s1 = run_batch(1)
    h2, s2 = run_batch(2)
    assert np.array_equal(h1, h2)
    assert s1.tobytes() == s2.tobytes()
    assert len(set(h1.tolist())) == len(h1)  # the pushes made every world differ


def test_batch_world_matches_a_single_world():
    world, boxes = stack_world()
    batch = janus2d.WorldBatch(world, 3, threads=2)
    world.step(DT, steps=40)
    batch.step(DT, steps=40)
    assert all(h == world.state_hash() for h in batch.state_hashes())
    assert np.array_equal(batch.get_state(boxes)[1], world.get_state(boxes))
    assert batch.world(2).state_hash() == world.state_hash()


def test_batch_forces_contacts_and_reset():
    world = janus2d.World(gravity=(0.0, 0.0))
    b = world.create_body("dynamic")
    world.create_circle(b, 0.5)
    m = world.mass(b)
    batch = janus2d.WorldBatch(world, 4, threads=2)
    f = np.zeros((4, 1, 3))
    f[:, 0, 0] = [0.0, 1.0, 2.0, 3.0]
    batch.apply_forces([b], f)
    batch.step(0.5)
    vx = batch.get_state([b])[:, 0, 3]
    assert np.allclose(vx * m, f[:, 0, 0] * 0.5, atol=1e-5)
    start = world.state_hash()
    batch.reset_where([True, False, False, True])
    h = batch.state_hashes()
    assert h[0] == start and h[3] == start and h[1] != start
    assert batch.get_contact_counts([b]).tolist() == [[0]] * 4


def test_batch_errors():
    world, boxes = stack_world()
    with pytest.raises(errors.BatchError) as e:
        janus2d.WorldBatch(world, 0)
    assert e.value.kind == "Empty"
    batch = janus2d.WorldBatch(world, 2)
    with pytest.raises(ValueError, match="shape"):
        batch.set_velocities(boxes, np.zeros((3, len(boxes), 3)))
    with pytest.raises(errors.InvalidInputError) as e:
        batch.step(-1.0)
    assert e.value.world == 0
    with pytest.raises(errors.BatchError) as e:
        batch.reset(5)
    assert e.value.kind == "WorldIndex"
    with pytest.raises(errors.BatchError):
        batch.threads = 0
    v = np.zeros((2, len(boxes), 3))
    v[1, 0, 0] = np.inf
    with pytest.raises(errors.InvalidInputError) as e:
        batch.set_velocities(boxes, v)
    assert e.value.world == 1


@pytest.mark.parametrize(
    "env_id,kwargs",
    [
        ("janus2d/LunarLander-v0", {}),
        ("janus2d/LunarLander-v0", {"continuous": True}),
        ("janus2d/LunarLanderPortal-v0", {}),
        ("janus2d/BipedalWalker-v0", {}),
        ("janus2d/BipedalWalkerHardcore-v0", {}),
    ],
)
def test_env_checker_passes(env_id, kwargs):
    env = gym.make(env_id, render_mode="rgb_array", **kwargs)
    check_env(env.unwrapped, skip_render_check=False)
    obs, _ = env.reset(seed=3)
    assert env.observation_space.contains(obs)
    frame = env.render()
    assert frame.shape == (400, 600, 3) and frame.dtype == np.uint8
    env.close()


def test_lander_spaces_are_gymnasiums():
    env = gym.make("janus2d/LunarLander-v0")
    assert env.action_space == gym.spaces.Discrete(4)
    assert env.observation_space.shape == (8,)
    assert env.observation_space.high[0] == 2.5 and env.observation_space.high[6] == 1.0
    assert env.spec.max_episode_steps == 1000
    walker = gym.make("janus2d/BipedalWalker-v0")
    assert walker.action_space.shape == (4,) and walker.observation_space.shape == (24,)
    assert walker.spec.max_episode_steps == 1600


def test_lander_that_does_nothing_falls_and_lands_or_crashes():
    env = gym.make("janus2d/LunarLander-v0")
    obs, _ = env.reset(seed=0)
    y0 = obs[1]
    assert 1.2 < y0 < 1.5  # starts at the top of the view
    total, last = 0.0, 0.0
    for _ in range(1000):
        obs, last, term, trunc, _ = env.step(0)
        total += last
        if term or trunc:
            break
    assert term  # it hit the ground (crash) or came to rest
    assert last in (-100.0, 100.0)
    assert obs[1] < y0


def test_lander_main_engine_slows_the_fall():
    def fall(action):
        env = gym.make("janus2d/LunarLander-v0")
        env.reset(seed=7)
        for _ in range(20):
            obs, *_ = env.step(action)
        return obs[3]

    assert fall(2) > fall(0) + 0.5  # vertical speed (scaled) with thrust vs without


def test_same_seed_same_episode():
    def episode():
        env = gym.make("janus2d/BipedalWalker-v0")
        env.reset(seed=11)
        env.action_space.seed(11)
        out = []
        for _ in range(50):
            obs, r, term, trunc, _ = env.step(env.action_space.sample())
            out.append(r)
            if term:
                break
        return np.array(out), obs

    (r1, o1), (r2, o2) = episode(), episode()
    assert np.array_equal(r1, r2) and np.array_equal(o1, o2)


def test_vector_lander_rollout_with_autoreset():
    envs = LunarLanderVector(16, threads=2)
    obs, _ = envs.reset(seed=5)
    assert obs.shape == (16, 8) and obs.dtype == np.float32
    rng = np.random.default_rng(5)
    episodes, returns, running = 0, [], np.zeros(16)
    for _ in range(400):
        obs, rew, term, trunc, _ = envs.step(rng.integers(0, 4, size=16))
        assert envs.observation_space.contains(obs) or np.all(np.abs(obs[:, :6]) < 100)
        running += rew
        done = term | trunc
        returns += running[done].tolist()
        running[done] = 0.0
        episodes += int(done.sum())
    assert episodes >= 16  # every lander ended at least one episode in 400 steps
    assert -1000.0 < np.mean(returns) < 100.0
    envs.close()


def test_vector_lander_is_thread_count_independent():
    def roll(threads):
        envs = LunarLanderVector(8, threads=threads)
        obs, _ = envs.reset(seed=9)
        rng = np.random.default_rng(9)
        for _ in range(120):
            obs, rew, *_ = envs.step(rng.integers(0, 4, size=8))
        return obs, rew

    (o1, r1), (o2, r2) = roll(1), roll(2)
    assert o1.tobytes() == o2.tobytes() and np.array_equal(r1, r2)


def test_vector_walker_steps():
    envs = BipedalWalkerVector(4, threads=2)
    obs, _ = envs.reset(seed=2)
    assert obs.shape == (4, 24)
    lidar = obs[:, 14:]
    assert np.all((lidar > 0.0) & (lidar <= 1.0))
    assert np.any(lidar < 1.0)  # the downward rays see the ground
    for _ in range(20):
        obs, rew, term, trunc, _ = envs.step(np.zeros((4, 4)))
    assert rew.shape == (4,) and np.all(np.isfinite(rew))


def test_hardcore_walker_course_has_obstacles_and_the_default_is_unchanged():
    from janus2d.envs.walker import STEP, TERRAIN_STEPS, build_world, hardcore_terrain, terrain

    kinds = set()
    for seed in range(4):
        ys, polys = hardcore_terrain(np.random.default_rng(seed))
        assert len(ys) == TERRAIN_STEPS
        # The ground drops 4 steps into a pit (and climbs out of it).
        assert np.isclose(np.diff(ys).min(), -4 * STEP)
        for p in polys:
            size = (round((p[1][0] - p[0][0]) / STEP, 6), round((p[2][1] - p[1][1]) / STEP, 6))
            # A stair (4 wide, 1 high), a pit wall (1 by 4), a stump (1 or 2 square).
            assert size in {(4, 1), (1, 4), (1, 1), (2, 2)}, size
            kinds.add({(4, 1): "stair", (1, 4): "pit", (1, 1): "stump", (2, 2): "stump"}[size])
    assert kinds == {"stair", "pit", "stump"}
    normal = terrain(np.random.default_rng(4))
    assert np.abs(np.diff(normal)).max() < 4 * STEP  # no pit in the normal course
    # The build before the hardcore option (f32): the same world, the same
    # walk below. The walk's digest changed at stop 47 (9d3aa907e2365929
    # before): the f32 build reads the hips' and knees' angles through its
    # own atan2 (`math::solver_atan2`); the world hash, taken before any
    # step, did not.
    pinned = janus2d.real_bytes() == 4
    world, _ = build_world(np.random.default_rng(4))
    if pinned:
        assert world.state_hash() == 0xB201134B968E3ADE

    def walk(env_id):
        env = gym.make(env_id)
        env.reset(seed=9)
        xs = []
        for _ in range(60):
            obs, *_ = env.step(np.array([0.5, -0.5, -0.5, 0.5], dtype=np.float32))
            xs.append(obs.copy())
        return np.array(xs)

    normal_run = walk("janus2d/BipedalWalker-v0")
    if pinned:
        digest = hashlib.sha256(normal_run.tobytes()).hexdigest()
        assert digest.startswith("5260cf16a9ec7464")
    hard = walk("janus2d/BipedalWalkerHardcore-v0")
    assert hard.tobytes() != normal_run.tobytes()
    assert gym.spec("janus2d/BipedalWalkerHardcore-v0").max_episode_steps == 2000
    vec = BipedalWalkerVector(2, hardcore=True)
    assert vec.max_episode_steps == 2000
    obs, _ = vec.reset(seed=1)
    for _ in range(10):
        obs, rew, *_ = vec.step(np.zeros((2, 4)))
    assert np.all(np.isfinite(rew))
