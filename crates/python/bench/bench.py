"""janus2d's Python side, measured in one run: the batches' thread
scaling (WorldBatch stepping lander worlds; LanderBatch, the lander's
whole environment step in Rust), and LunarLander environment steps per
second beside Gymnasium's Box2D one (when ``gymnasium[box2d]`` is
installed), single and vectorised (8, 64, 256), with the random policy's
returns. Each section prints the load average (1 minute) before it.

    python crates/python/bench/bench.py            # everything
    python crates/python/bench/bench.py --quick    # fewer repeats

Run it on an idle machine (nothing else compiling): on 2 cores, one busy
process elsewhere halves the 2-thread figures. Before each timed run it
waits (up to ``--idle-wait`` seconds) for a moment with the CPUs idle
(under 10 % busy over a second, from ``/proc/stat``), both engines alike.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

import janus2d
from janus2d.envs.lander import build_world


IDLE_WAIT = 60.0


def cpu_busy(interval=1.0):
    """The fraction of CPU time busy over `interval` s (None off Linux)."""
    def sample():
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:]]
        return v[0] + v[1] + v[2] + v[5] + v[6], v[3] + v[4]

    try:
        b0, i0 = sample()
        time.sleep(interval)
        b1, i1 = sample()
    except OSError:
        return None
    total = (b1 - b0) + (i1 - i0)
    return (b1 - b0) / total if total else 0.0


def wait_idle():
    """Waits up to IDLE_WAIT s for a second with the CPUs under 10 % busy."""
    start = time.monotonic()
    while time.monotonic() - start < IDLE_WAIT:
        busy = cpu_busy()
        if busy is None or busy < 0.10:
            return


def best_of(repeats, fn):
    times = []
    for _ in range(repeats):
        wait_idle()
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def batch_scaling(worlds=256, steps=100, repeats=5):
    """Steps/s of a batch of `worlds` lander worlds (a lander on its legs
    above random ground, falling and landing) on 1 and 2 threads."""
    world, h = build_world(np.random.default_rng(0))
    rows = []
    for threads in (1, 2):
        def run():
            batch = janus2d.WorldBatch(world, worlds, threads=threads)
            batch.step(1 / 50, steps=steps)

        # The batch's creation is outside the timing: time a build alone.
        build = best_of(repeats, lambda: janus2d.WorldBatch(world, worlds, threads=threads))
        t = best_of(repeats, run) - build
        rows.append((threads, worlds * steps / t))
    return rows


def lander_batch_scaling(landers=256, steps=200, repeats=5):
    """Env-steps/s of a LanderBatch (random discrete actions, autoreset)
    on 1 and 2 threads: the Rust environment step without Python."""
    rng = np.random.default_rng(0)
    actions = rng.integers(0, 4, size=(steps, landers))
    rows = []
    for threads in (1, 2):
        batch = janus2d.LanderBatch(landers, threads=threads, autoreset=True,
                                    max_episode_steps=1000)

        def run():
            batch.reset(1)
            for a in actions:
                batch.step(a)

        reset = best_of(repeats, lambda: batch.reset(1))
        t = best_of(repeats, run) - reset
        rows.append((threads, landers * steps / t))
    return rows


def load():
    return f"load average {os.getloadavg()[0]:.2f}"


def lander_returns(make_env, episodes, seed):
    env = make_env()
    out = []
    for k in range(episodes):
        env.reset(seed=seed + k)
        env.action_space.seed(seed + k)
        total, done = 0.0, False
        while not done:
            _, r, term, trunc, _ = env.step(env.action_space.sample())
            total += r
            done = term or trunc
        out.append(total)
    return np.array(out)


def env_rate(make_env, steps, seed=0, repeats=3):
    """Best of `repeats` runs of `steps` random steps (a busy neighbour
    only ever slows a run down)."""
    env = make_env()
    env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    actions = [int(a) for a in rng.integers(0, 4, size=steps)]
    best = 0.0
    for _ in range(repeats):
        wait_idle()
        t0 = time.perf_counter()
        for a in actions:
            _, _, term, trunc, _ = env.step(a)
            if term or trunc:
                env.reset()
        best = max(best, steps / (time.perf_counter() - t0))
    return best


def vector_rate(make_vec, n, steps, seed=0, repeats=3):
    """Best of `repeats` runs of `steps` random vector steps."""
    envs = make_vec(n)
    envs.reset(seed=seed)
    rng = np.random.default_rng(seed)
    actions = [rng.integers(0, 4, size=n) for _ in range(steps)]
    best = 0.0
    for _ in range(repeats):
        wait_idle()
        t0 = time.perf_counter()
        for a in actions:
            envs.step(a)
        best = max(best, n * steps / (time.perf_counter() - t0))
    envs.close()
    return best


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--threads", type=int, default=2, help="threads of janus2d's vector envs")
    ap.add_argument("--idle-wait", type=float, default=60.0,
                    help="longest wait for an idle moment before each timed run, s")
    args = ap.parse_args()
    global IDLE_WAIT
    IDLE_WAIT = args.idle_wait
    repeats = 2 if args.quick else 5
    episodes = 20 if args.quick else 100

    print(f"== WorldBatch: 256 lander worlds, 100 steps, best of {repeats} ({load()})")
    rows = batch_scaling(repeats=repeats)
    print(f"{'threads':>8} {'world-steps/s':>14} {'speed-up':>9}")
    for threads, rate in rows:
        print(f"{threads:>8} {rate:>14.0f} {rate / rows[0][1]:>9.2f}")

    print()
    print(f"== LanderBatch: 256 landers, random actions, 200 steps, best of {repeats} ({load()})")
    rows = lander_batch_scaling(repeats=repeats)
    print(f"{'threads':>8} {'env-steps/s':>14} {'speed-up':>9}")
    for threads, rate in rows:
        print(f"{threads:>8} {rate:>14.0f} {rate / rows[0][1]:>9.2f}")

    import gymnasium as gym

    import janus2d.envs  # noqa: F401
    from janus2d.envs import LunarLanderVector

    try:
        import Box2D  # noqa: F401

        have_box2d = True
    except ImportError:
        have_box2d = False

    print()
    print(f"== LunarLander, random actions: environment steps per second ({load()})")
    print(f"   janus2d's vector envs on {args.threads} threads; Gymnasium's: sync vector env")
    single_steps = 5000 if args.quick else 20000
    j_single = env_rate(lambda: gym.make("janus2d/LunarLander-v0"), single_steps)
    g_single = (
        env_rate(lambda: gym.make("LunarLander-v3"), single_steps) if have_box2d else None
    )
    print(f"{'envs':>6} {'janus2d':>12} {'(1 thread)':>12} {'gymnasium+Box2D':>16} {'ratio':>7}")

    def line(n, j, j1, g):
        gs = f"{g:>16.0f}" if g else f"{'n/a':>16}"
        ratio = f"{j / g:>7.2f}" if g else f"{'':>7}"
        j1s = f"{j1:>12.0f}" if j1 else f"{'':>12}"
        print(f"{n:>6} {j:>12.0f} {j1s} {gs} {ratio}", flush=True)

    line(1, j_single, None, g_single)
    for n in (8, 64, 256):
        steps = max(50, (5000 if args.quick else 20000) // n)
        j = vector_rate(lambda k: LunarLanderVector(k, threads=args.threads), n, steps)
        j1 = vector_rate(lambda k: LunarLanderVector(k, threads=1), n, steps)
        g = None
        if have_box2d:
            g = vector_rate(
                lambda k: gym.make_vec("LunarLander-v3", num_envs=k, vectorization_mode="sync"),
                n,
                steps,
            )
        line(n, j, j1, g)
        print(f"       ({load()})")

    print()
    print(f"== random policy returns over {episodes} episodes ({load()})")
    for name, make in [("janus2d", lambda: gym.make("janus2d/LunarLander-v0"))] + (
        [("gymnasium+Box2D", lambda: gym.make("LunarLander-v3"))] if have_box2d else []
    ):
        r = lander_returns(make, episodes, seed=1000)
        q = np.percentile(r, [10, 50, 90])
        print(
            f"{name:>16}: mean {r.mean():7.1f}  std {r.std():6.1f}  "
            f"p10 {q[0]:7.1f}  median {q[1]:7.1f}  p90 {q[2]:7.1f}"
        )
    if not have_box2d:
        print("(gymnasium[box2d] is not installed: no Box2D column)")


if __name__ == "__main__":
    main()
