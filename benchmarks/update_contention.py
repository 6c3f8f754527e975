"""The PPO update when other processes share the cores: what two runs on one machine do to each other.

``unicross train`` and ``unicross distill`` alternate: the env workers collect, then the main process
updates on every core (``torch.set_num_threads(cores)``). On a machine of its own that is right: the
workers sleep during the update. When a second run's workers keep the cores busy, the update's
OpenMP threads wait for each other at every op's barrier while the scheduler runs someone else.
This script times the real update (``unicross.rl.algorithm.PPO`` at the default config and the
Allegro observation and action sizes, one 1024-frame batch of random data) in a fresh process per
setting, alone and next to ``--hogs`` busy processes (stand-ins for another run's env workers):

    python benchmarks/update_contention.py [--hogs 2] [--repeats 5] [--json docs/update_contention.json]

Settings: update threads = cores (today's default) or 1, and ``OMP_WAIT_POLICY`` unset or PASSIVE
(it must be set before torch starts, hence the fresh processes). Ratios of one run are what count:
these machines are shared and noisy.
"""
from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _hog(stop):
    while not stop.is_set():
        sum(range(10000))


def time_update(threads: int, repeats: int) -> float:
    """Median seconds of one PPO update on a random 1024-frame batch with ``threads`` torch threads."""
    import torch
    sys.path.insert(0, ROOT)
    from unicross.config import load_config
    from unicross.rl.algorithm import PPO
    from unicross.rl.collector import make_buffer
    from unicross.rl.models import OBS_KEYS
    torch.set_num_threads(threads)
    dims, n_act, n, t = dict(hand=44, object=105, goal=55), 22, 2, 512
    cfg = load_config("ppo", None)
    torch.manual_seed(0)
    algo = PPO(dims, n_act, cfg, frames_per_batch=n * t)
    buf = make_buffer(n, t, dims, n_act)
    for k in OBS_KEYS:
        buf[k] = torch.randn(n, t, dims[k])
        buf["next", k] = torch.randn(n, t, dims[k])
    with torch.no_grad():
        loc, scale = algo.actor(*(buf[k] for k in OBS_KEYS))
        buf["loc"], buf["scale"], buf["action"] = loc, scale, loc + scale * torch.randn(loc.shape)
        buf["action_log_prob"] = algo.policy.get_dist(buf.select(*OBS_KEYS)).log_prob(buf["action"])
    buf["next", "reward"] = torch.randn(n, t, 1)
    algo.update(buf.clone())  # warm-up
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        algo.update(buf.clone())
        times.append(time.perf_counter() - t0)
    return sorted(times)[len(times) // 2]


def run_setting(threads: int, passive: bool, hogs: int, repeats: int) -> float:
    env = dict(os.environ)
    env.pop("OMP_WAIT_POLICY", None)
    if passive:
        env["OMP_WAIT_POLICY"] = "PASSIVE"
    ctx = mp.get_context("spawn")
    stop = ctx.Event()
    procs = [ctx.Process(target=_hog, args=(stop,), daemon=True) for _ in range(hogs)]
    for p in procs:
        p.start()
    try:
        out = subprocess.run([sys.executable, __file__, "--child", str(threads), str(repeats)], env=env,
                             capture_output=True, text=True, check=True)
    finally:
        stop.set()
        for p in procs:
            p.join()
    return float(out.stdout.strip().splitlines()[-1])


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--hogs", type=int, default=None, help="busy processes beside the update (default: cores)")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--json", default=None)
    p.add_argument("--child", nargs=2, type=int, help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.child:
        print(time_update(*args.child))
        return
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    hogs = cores if args.hogs is None else args.hogs
    rows = []
    for threads in sorted({cores, 1}, reverse=True):
        for passive in (False, True):
            for h in (0, hogs):
                s = run_setting(threads, passive, h, args.repeats)
                rows.append(dict(threads=threads, omp_wait_policy="PASSIVE" if passive else "default", hogs=h,
                                 seconds=round(s, 4)))
                print(f"update threads {threads:2d}  OMP_WAIT_POLICY {rows[-1]['omp_wait_policy']:8s}  "
                      f"busy processes {h}: {s:.3f} s per 1024-frame update", flush=True)
    base = next(r["seconds"] for r in rows if r["threads"] == cores and r["omp_wait_policy"] == "default"
                and r["hogs"] == 0)
    for r in rows:
        r["vs_default_alone"] = round(r["seconds"] / base, 2)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(dict(cores=cores, hogs=hogs, repeats=args.repeats, rows=rows), f, indent=1)
    print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
