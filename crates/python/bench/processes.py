"""Scale out: one WorldBatch per process, processes from the standard
library's pool (any queue or Ray does the same: see docs/python.md).

    python crates/python/bench/processes.py --procs 2 --envs 256 --steps 200

Each process runs a LunarLanderVector of ``--envs`` landers on one thread
with random actions and reports its environment steps per second; the
total and the per-core figure are printed.
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np


def rollout(seed: int, envs: int, steps: int) -> float:
    """One process's work: a batch of landers, one thread."""
    from janus2d.envs import LunarLanderVector

    vec = LunarLanderVector(envs, threads=1)
    vec.reset(seed=seed)
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    for _ in range(steps):
        vec.step(rng.integers(0, 4, size=envs))
    return envs * steps / (time.perf_counter() - t0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--procs", type=int, default=2)
    ap.add_argument("--envs", type=int, default=256)
    ap.add_argument("--steps", type=int, default=200)
    args = ap.parse_args()
    with ProcessPoolExecutor(args.procs) as pool:
        t0 = time.perf_counter()
        rates = list(pool.map(rollout, range(args.procs), [args.envs] * args.procs,
                              [args.steps] * args.procs))
        wall = time.perf_counter() - t0
    total = args.procs * args.envs * args.steps
    print(f"{args.procs} processes x {args.envs} landers x {args.steps} steps")
    for i, r in enumerate(rates):
        print(f"  process {i}: {r:,.0f} env-steps/s")
    print(f"sum of per-process rates: {sum(rates):,.0f} env-steps/s "
          f"({sum(rates) / args.procs:,.0f} per core)")
    print(f"wall clock incl. start-up: {total / wall:,.0f} env-steps/s")


if __name__ == "__main__":
    main()
