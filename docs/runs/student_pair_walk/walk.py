"""Where each worker seed's pair walk starts and what its first PAIRS pairs hold (modes, shape groups).

    python docs/runs/student_pair_walk/walk.py [--order sequential|balanced] [--seeds 0 1 2 3] [--pairs 300]

Builds the distillation env (`UniCross-MultiSkill-v1`, all ten modes, the 400 training objects) once per worker
seed, resets it with that seed as the lean collector does (worker seed = run seed + rank) and counts the pairs
from the cursor on. Eager step math (nothing is stepped).
"""
import argparse
import collections
import os

os.environ.setdefault("UNICROSS_COMPILE", "0")

import gymnasium as gym  # noqa: E402

import unicross  # noqa: E402,F401
from unicross import formulation as F  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--order", default="sequential", choices=["sequential", "balanced"])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3])
    ap.add_argument("--pairs", type=int, default=300)
    args = ap.parse_args()
    for seed in args.seeds:
        env = gym.make("UniCross-MultiSkill-v1", obs_mode="state", sim_backend="physx_cpu", render_backend="none",
                       num_envs=1, object_limit=None, reconfiguration_freq=2, config={"pair_order": args.order})
        u = env.unwrapped
        env.reset(seed=seed)
        start, n = u._pair_cursor - 1, len(u._pairs)
        window = [u._pairs[(start + i) % n] for i in range(args.pairs)]
        modes = collections.Counter(F.MODES[m] for _, m in window)
        groups = collections.Counter("-".join(u.object_names[o].split("-")[:2]) for o, _ in window)
        print(f"worker seed {seed}: start {start} of {n}; modes {dict(modes)}; shape groups {dict(groups)}")
        env.close()


if __name__ == "__main__":
    main()
