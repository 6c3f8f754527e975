"""Training frames/s vs CPU env workers, against the rate of one env alone, in one run.

single env:  ``task.step`` of one in-process grasp env with small random actions (resets and scene
             rebuilds included, as in training), no policy: the physics + task rate of one core;
training W:  ``unicross train``'s loop (lean collector with W worker processes, the actor inside
             each, GAE and the real PPO update at the default batch of 1024 frames), frames/s over
             ``--iterations`` iterations after one warm-up iteration;
efficiency:  training W / (W x single env)  (target: >= 0.8 at 2 workers, issue "Training at the
             speed of physics"); the single env is measured before and after the training rows and
             the ratio uses their mean (``efficiency_range``: against the faster and the slower of
             the two; a machine whose speed drifts during the run shows here, and the script warns
             when the two differ by more than 15%);
collect_efficiency:  the same for the collection alone (frames over the iterations' time outside the
             update: waiting for the batch and the bookkeeping; None with ``collector.overlap``,
             where that wait is not the collection's time): what the workers lose to one env
             alone, before the update.

``--compare-overlap``: each worker count twice, collection then update (the default) and with
``collector.overlap`` (the workers collect the next batch during the update), in the same run; one
worker (in-process collection) without overlap only. ``--update-devices cpu cuda``: each row once per
``optim.update_device`` (the learner on the CPU, or on a GPU with the workers acting with a CPU copy),
in the same run.

Writes JSON (``--json``) and a PNG curve (``--png``; ``--from-json`` draws it from an earlier run's
JSON). ``--set section.key=value`` overrides ``configs/ppo.yaml`` as ``unicross train --set`` does (e.g. the in-hand experts' 4096-frame batches
and ``optim.kl_stop``), for the training rows only.

    python benchmarks/scaling.py [--workers 1 2] [--iterations 4] [--set ...] [--json docs/scaling.json] [--png docs/scaling.png]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time

import torch

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import gymnasium as gym  # noqa: E402

import unicross  # noqa: E402,F401
from unicross.cli import parse_sets  # noqa: E402
from unicross.config import deep_merge  # noqa: E402
from unicross.rl.ppo import PPOTrainer  # noqa: E402


def single_env_rate(steps: int, seed: int = 0) -> float:
    env = gym.make("UniCross-Grasp-v1", obs_mode="state_dict", render_backend="none", sim_backend="physx_cpu",
                   reconfiguration_freq=4)
    u = env.unwrapped
    g = torch.Generator().manual_seed(seed)
    u.reset(seed=seed)
    for _ in range(20):  # warm up: the first step compiles (or loads) the command math
        u.step(torch.zeros(1, u.hand_spec.dof))
    u.reset(seed=seed)
    n = 0
    t0 = time.perf_counter()
    while n < steps:
        a = (torch.rand(1, u.hand_spec.dof, generator=g) * 2 - 1) * 0.2
        _, _, term, trunc, _ = u.step(a)
        n += 1
        if bool((term | trunc).any()):
            u.reset()
    rate = n / (time.perf_counter() - t0)
    env.close()
    return rate


def training_rate(workers: int, iterations: int, overrides: dict | None = None) -> dict:
    run = os.path.join(tempfile.mkdtemp(), "r")
    base = dict(env=dict(num_envs=workers), collector=dict(total_frames=10 ** 9),
                logging=dict(eval_trials=0, final_eval_trials=0, checkpoint_every=10 ** 6))
    t = PPOTrainer(run, "grasp", progress=False, overrides=deep_merge(overrides or {}, base, strict=False))
    try:
        t.train(max_iterations=1, eval_at_ends=False)  # warm up (first batch fits the statistics)
        f0, t0 = t.frames, time.perf_counter()
        t.train(max_iterations=iterations, eval_at_ends=False)
        fps = (t.frames - f0) / (time.perf_counter() - t0)
        rows = [json.loads(line) for line in open(os.path.join(run, "metrics.jsonl"))][-iterations:]
        coll = sum(r["collect_s"] for r in rows)
        upd = sum(r["update_s"] for r in rows)
    finally:
        t.close()
    overlapped = bool(t.overlap)
    return dict(workers=workers, frames_per_iteration=t.collector.frames_per_batch, training_fps=round(fps, 1),
                collect_share=round(coll / (coll + upd), 3), update_share=round(upd / (coll + upd), 3),
                collect_fps=None if overlapped else round((t.frames - f0) / coll, 1),
                minibatch_steps=round(sum(r["minibatch_steps"] for r in rows) / len(rows), 1))


def plot(out: dict, path: str) -> None:
    """The PNG curve of a run's JSON: training frames/s per worker count (with and without overlap
    where both ran) against workers x one env alone."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows, single = out["rows"], out["single_env_steps_per_s"]
    ws = sorted({r["workers"] for r in rows})
    fig, ax = plt.subplots(figsize=(5, 3.5))
    for overlap, dev in sorted({(r["overlap"], r.get("update_device")) for r in rows}, key=str):
        sel = [r for r in rows if r["overlap"] == overlap and r.get("update_device") == dev]
        ax.plot([r["workers"] for r in sel], [r["training_fps"] for r in sel], "o-",
                label="training (PPO" + (f", update on {dev}" if dev else "") + (", overlapped)" if overlap else ")"))
    ax.plot(ws, [w * single for w in ws], "--", color="gray", label="workers x single env")
    ax.set_xticks(ws)
    ax.set_xlabel("env worker processes")
    ax.set_ylabel("frames/s")
    ax.set_title(f"Allegro grasp, {out['cores']} cores")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    p.add_argument("--iterations", type=int, default=4)
    p.add_argument("--env-steps", type=int, default=1500)
    p.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE", help="override configs/ppo.yaml")
    p.add_argument("--compare-overlap", action="store_true",
                   help="each worker count without and with collector.overlap (1 worker: without only; "
                        "overlapped collection runs in worker processes)")
    p.add_argument("--update-devices", nargs="+", default=None, metavar="DEVICE",
                   help="each row once per optim.update_device (e.g. cpu cuda), in the same run")
    p.add_argument("--json", default=None)
    p.add_argument("--png", default=None)
    p.add_argument("--from-json", default=None, metavar="JSON",
                   help="measure nothing: draw --png from an earlier run's JSON (e.g. one from a lent machine)")
    args = p.parse_args()
    if args.from_json:
        if not args.png:
            p.error("--from-json draws a PNG: give --png")
        with open(args.from_json) as f:
            plot(json.load(f), args.png)
        return
    overrides = parse_sets(args.set)
    single_before = single_env_rate(args.env_steps)
    rows = []
    for w in args.workers:
        for overlap in (((False, True) if w >= 2 else (False,)) if args.compare_overlap else (None,)):
            ov = overrides if overlap is None else deep_merge(overrides, {"collector": {"overlap": overlap}},
                                                             strict=False)
            for dev in args.update_devices or [None]:
                od = ov if dev is None else deep_merge(ov, {"optim": {"update_device": dev}}, strict=False)
                r = training_rate(w, args.iterations, od)
                r["overlap"] = bool(od.get("collector", {}).get("overlap", False))
                r["update_device"] = (od.get("optim") or {}).get("update_device")
                rows.append(r)
                print(json.dumps(r), flush=True)
    single_after = single_env_rate(args.env_steps, seed=1)
    single = (single_before + single_after) / 2
    lo, hi = sorted((single_before, single_after))
    if hi > 1.15 * lo:
        print(f"warning: one env alone ran at {single_before:.0f} steps/s before the training rows and "
              f"{single_after:.0f} after: this machine's speed drifted; the efficiencies use their mean",
              file=sys.stderr, flush=True)
    for r in rows:
        w = r["workers"]
        r["efficiency"] = round(r["training_fps"] / (w * single), 3)
        r["efficiency_range"] = [round(r["training_fps"] / (w * hi), 3), round(r["training_fps"] / (w * lo), 3)]
        r["collect_efficiency"] = None if r["collect_fps"] is None else round(r["collect_fps"] / (w * single), 3)
    out = dict(single_env_steps_per_s=round(single, 1),
               single_env_before_after=[round(single_before, 1), round(single_after, 1)],
               cores=os.cpu_count(), settings=args.set or [], rows=rows)
    print(json.dumps(out, indent=1))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)
    if args.png:
        plot(out, args.png)


if __name__ == "__main__":
    main()
