"""How much exploration noise does a shipped rotate gait tolerate?

PPO on top of a gait (``model.base_policy``) explores by adding Gaussian noise to the gait's
action. This script runs the gait with such noise, N(0, sigma^2) per action dimension and AR(1) in
time with coefficient ``rho`` (as ``collector.noise_correlation`` makes it; 0: white), on the finger
dims, the wrist dims or all of them, and prints the success and drop counts of the rotate protocol
(the evaluation's conditions; first ``--limit`` training objects per group x ``--trials``). Since the
clock gait steers the joint command back to its trajectory every step, a noise of sigma offsets the
finger targets by ~0.1 rad x sigma (the finger action scale) without accumulating.

    python benchmarks/gait_noise.py --gait allegro/rotate_y- --noise 0:none 0.1:fingers 0.37:all --rho 0.9
"""
from __future__ import annotations

import argparse
import json
import math
import multiprocessing as mp
import sys
from concurrent.futures import ProcessPoolExecutor

import torch

DIMS = {"none": [], "wrist": list(range(6)), "fingers": list(range(6, 22)), "all": list(range(22))}


def noisy_gait(gait_spec: str, sigma: float, dims: list, rho: float, seed: int):
    """The gait's action plus AR(1) Gaussian noise of std ``sigma`` on ``dims``, clipped to [-1, 1];
    the noise restarts from N(0, 1) at each episode's first step."""
    from unicross.gaits import make_gait_policy
    gait = make_gait_policy(gait_spec)
    gen = torch.Generator().manual_seed(seed)
    state = {}

    def policy(obs, u):
        base = gait(obs, u)
        if int(u.elapsed_steps[0]) == 0 or state.get("u") is not u:
            state.update(u=u, eps=torch.randn(base.shape, generator=gen))
        else:
            state["eps"] = rho * state["eps"] + math.sqrt(1 - rho ** 2) * torch.randn(base.shape, generator=gen)
        mask = torch.zeros(base.shape[-1])
        mask[dims] = 1.0
        return (base + sigma * state["eps"] * mask).clamp(-1.0, 1.0)
    return policy


def _shard(gait_spec: str, sigma: float, which: str, rho: float, objects: str, limit: int, trials: int, shard) -> list:
    torch.set_num_threads(1)
    import unicross  # noqa: F401  (registers the tasks)
    from unicross import evaluation as E
    from unicross.gaits import gait_mode, make_gait_policy
    from unicross.objects import get_object_set
    axis = gait_mode(make_gait_policy(gait_spec).gait_row).split("_")[1]
    policy = noisy_gait(gait_spec, sigma, DIMS[which], rho, seed=shard[0])
    return E.run_protocol("rotate", policy, get_object_set(objects, limit=limit), trials_per_object=trials, seed=0,
                          axes=[axis], progress=False, shard=shard)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--gait", default="allegro/rotate_y-", help="a shipped rotate gait or a gait search log")
    ap.add_argument("--noise", nargs="+", default=["0:none", "0.1:fingers", "0.37:wrist", "0.37:all"],
                    help="SIGMA:DIMS settings, DIMS in none, wrist, fingers, all")
    ap.add_argument("--rho", type=float, default=0.9, help="AR(1) coefficient of the noise in time (0: white)")
    ap.add_argument("--objects", default="train")
    ap.add_argument("--limit", type=int, default=8, help="first N objects per group")
    ap.add_argument("--trials", type=int, default=2, help="trials per object")
    ap.add_argument("--workers", type=int, default=2, help="processes (also the noise streams: one per worker)")
    ap.add_argument("--out", default=None, help="JSON lines, one per setting")
    args = ap.parse_args(argv)
    settings = []
    for s in args.noise:
        sigma, _, which = s.partition(":")
        if which not in DIMS:
            ap.error(f"--noise {s}: DIMS must be one of {sorted(DIMS)}")
        settings.append((float(sigma), which))
    from unicross.gaits import make_gait_policy
    make_gait_policy(args.gait)  # a missing gait fails before any simulation
    rows = []
    ctx = mp.get_context("spawn")
    with ProcessPoolExecutor(args.workers, mp_context=ctx) as ex:
        for sigma, which in settings:
            futs = [ex.submit(_shard, args.gait, sigma, which, args.rho, args.objects, args.limit, args.trials,
                              (i, args.workers)) for i in range(args.workers)]
            trials = [t for f in futs for t in f.result()]
            row = dict(gait=args.gait, sigma=sigma, dims=which, rho=args.rho, n=len(trials),
                       success=sum(t["success"] for t in trials), dropped=sum(t["dropped"] for t in trials))
            rows.append(row)
            print(json.dumps(row), flush=True)
    if args.out:
        with open(args.out, "w") as f:
            f.writelines(json.dumps(r) + "\n" for r in rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
