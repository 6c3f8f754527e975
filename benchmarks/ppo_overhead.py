"""Collector + PPO overhead on the CPU: training frames/s vs env-only frames/s, in one run.

env-only:  the same (Parallel)Env stepped by ``env.rollout`` with a random policy;
collect:   the TorchRL Collector with the expert policy (network inference included);
training:  Collector + GAE + PPO update, as ``unicross train`` runs it.
The overhead is 1 - training / env-only (target: <= 0.20).

    python benchmarks/ppo_overhead.py [--num-envs 2] [--iterations 6]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time


sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from unicross.rl.ppo import PPOTrainer  # noqa: E402


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--num-envs", type=int, default=2)
    p.add_argument("--iterations", type=int, default=6)
    p.add_argument("--json", default=None)
    args = p.parse_args()
    run = tempfile.mkdtemp()
    t = PPOTrainer(os.path.join(run, "r"), "grasp", progress=False,
                   overrides=dict(env=dict(num_envs=args.num_envs, reconfiguration_freq=0),
                                  collector=dict(total_frames=10 ** 9), logging=dict(eval_trials=0, checkpoint_every=10 ** 6)))
    frames = t.frames_per_batch * args.iterations
    steps = frames // t.batch_envs
    t.env.rollout(8, break_when_any_done=False)  # warm up workers
    t0 = time.perf_counter()
    t.env.rollout(steps, break_when_any_done=False)
    env_fps = frames / (time.perf_counter() - t0)
    t.train(max_iterations=1, eval_at_ends=False)  # warm up
    f0, t0 = t.frames, time.perf_counter()
    t.train(max_iterations=args.iterations, eval_at_ends=False)
    train_fps = (t.frames - f0) / (time.perf_counter() - t0)
    rows = [r for r in open(os.path.join(run, "r", "metrics.csv")).read().splitlines()[1:]][-args.iterations:]
    hdr = open(os.path.join(run, "r", "metrics.csv")).readline().strip().split(",")
    coll = sum(float(dict(zip(hdr, r.split(",")))["collect_s"]) for r in rows)
    upd = sum(float(dict(zip(hdr, r.split(",")))["update_s"]) for r in rows)
    out = dict(num_envs=args.num_envs, frames_per_iteration=t.frames_per_batch, env_only_fps=round(env_fps, 1),
               training_fps=round(train_fps, 1), overhead=round(1 - train_fps / env_fps, 3),
               collect_share=round(coll / (coll + upd), 3), update_share=round(upd / (coll + upd), 3))
    print(json.dumps(out, indent=1))
    t.close()
    if args.json:
        json.dump(out, open(args.json, "w"), indent=1)


if __name__ == "__main__":
    main()
