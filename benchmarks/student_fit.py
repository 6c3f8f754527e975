"""How well can a student network fit its teachers' labels at all? An offline diagnosis of a DAgger run.

``unicross distill`` logs the student's per-mode action MSE on its own replay batches; for the
student of ten it stays at 0.02-0.04 on the rotate modes while grasp, relocate and translate reach
1e-3 or less. This script separates the two usual causes: too small a network or too few gradient
steps (a larger budget on the same data fits the rotate labels), against labels that no function
of the observation this size fits (the held-out error stays high whatever the budget). It loads
the replay buffer of a DAgger checkpoint (its observations and expert labels), holds out a
fraction of it, fits a fresh student (the run's architecture, or ``--main-hidden``) with Adam and
a cosine learning-rate decay, and prints the per-mode MSE on the fitted and the held-out samples,
next to each mode's label variance (the error of predicting the mean label)::

    python benchmarks/student_fit.py runs/student10_s0 --steps 20000 --json docs/runs/student_fit/s0.json
    python benchmarks/student_fit.py runs/student10_s0 --steps 20000 --main-hidden 1024 512 256
    python benchmarks/student_fit.py runs/student10_s0 --steps 20000 --relabel rotate_y-=runs/clone/policy.pt

``--relabel MODE=POLICY`` replaces that mode's labels by another teacher's mean actions on the same
states (clamped to [-1, 1], as DAgger's teachers label): would the student fit that teacher better?

``--init`` starts from the run's own student (its weights and observation statistics) instead of a fresh one, and
``--weighted`` weighs the rows as the run did (``optim.mode_weights``): would more steps on the same data polish the
run's student? ``--out`` writes the run's checkpoint with the fitted weights, for ``unicross eval`` or drift.py::

    python benchmarks/student_fit.py runs/x0_1800 --init --weighted --steps 10000 --lr-floor 0 --threads 2 \
        --out runs/x0_1800_polished.pt

No simulation: a few minutes on one core for 20k steps of 1024 samples with the default network.
The held-out samples come from the same rollouts as the fitted ones (a random split), so they
measure fitting, not the student's own new states (DAgger's fresh error).
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import torch
from torchrl.data import Bounded, LazyTensorStorage, TensorDictReplayBuffer

from unicross import formulation as F
from unicross.rl.dagger import check_l1, distill_loss, mode_weight_vector
from unicross.rl.models import OBS_KEYS, make_models


def load_buffer(run: Path):
    """(TensorDict of the run's replay buffer, the checkpoint) of a ``unicross distill`` run."""
    ck = torch.load(run / "checkpoint.pt", map_location="cpu", weights_only=False)
    replay = ck.get("replay_dir")
    if not replay or not (run / replay).exists():
        raise FileNotFoundError(f"{run}: the checkpoint names no replay buffer on disk ({replay!r})")
    rb = TensorDictReplayBuffer(storage=LazyTensorStorage(ck["config"]["buffer"]["capacity"]))
    rb.loads(run / replay)
    return rb.storage[: len(rb)], ck


def per_mode(err: torch.Tensor, mode: torch.Tensor) -> dict:
    return {m: float(err[mode == i].mean()) for i, m in enumerate(F.MODES) if bool((mode == i).any())}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("run", help="a unicross distill run directory (checkpoint.pt and its replay buffer)")
    p.add_argument("--steps", type=int, default=20000)
    p.add_argument("--batch-size", type=int, default=1024)
    p.add_argument("--lr", type=float, default=3e-4, help="start of the cosine decay (to lr x --lr-floor)")
    p.add_argument("--lr-floor", type=float, default=0.01, help="where the cosine decay ends, as a fraction of --lr")
    p.add_argument("--init", action="store_true", help="start from the run's student (weights and observation "
                   "statistics) instead of a fresh network")
    p.add_argument("--weighted", action="store_true", help="weigh the rows by the run's optim.mode_weights")
    p.add_argument("--out", default=None, help="write the run's checkpoint with the fitted weights here")
    p.add_argument("--holdout", type=float, default=0.1, help="fraction of the buffer held out")
    p.add_argument("--main-hidden", type=int, nargs="+", default=None, help="default: the run's model.main_hidden")
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--relabel", action="append", default=[], metavar="MODE=POLICY",
                   help="label MODE's states with POLICY (a checkpoint or <hand>/<mode>) instead; repeatable")
    p.add_argument("--l1", type=float, default=0.0, help="add this times the absolute action error to the loss "
                   "(unicross distill's optim.l1; 0: the plain MSE)")
    p.add_argument("--json", default=None)
    a = p.parse_args(argv)
    if not 0 < a.holdout < 1:
        p.error("--holdout must be in (0, 1)")
    if not 0 <= a.lr_floor <= 1:
        p.error("--lr-floor must be in [0, 1]")
    try:
        check_l1(a.l1)
    except ValueError as e:
        p.error(str(e))
    if a.init and a.main_hidden:
        p.error("--init keeps the run's network: leave out --main-hidden")
    torch.set_num_threads(a.threads)
    torch.manual_seed(a.seed)
    relabel = {}
    for spec in a.relabel:
        mode, _, path = spec.partition("=")
        if mode not in F.MODES or not path:
            p.error(f"--relabel takes MODE=POLICY with MODE in {list(F.MODES)}, got {spec!r}")
        relabel[mode] = path
    data, ck = load_buffer(Path(a.run))
    if relabel:  # DAgger's own labelling: each mode's checkpoint checked and its action clamped
        from unicross.rl.dagger import Teachers
        teachers = Teachers({m: Path(path) for m, path in relabel.items()}, "cpu")
        sel = torch.isin(data["mode"], torch.tensor([F.MODES.index(m) for m in relabel]))
        data["expert_action"][sel] = teachers(data[sel])
    n = data.shape[0]
    perm = torch.randperm(n)
    n_test = int(n * a.holdout)
    test, fit = data[perm[:n_test]], data[perm[n_test:]]
    model_cfg = dict(ck.get("config", {}).get("model", {}))
    if a.main_hidden:
        model_cfg["main_hidden"] = list(a.main_hidden)
    dims = {k: data[k].shape[-1] for k in OBS_KEYS}
    n_act = data["expert_action"].shape[-1]
    policy, _, norm = make_models(dims, n_act, Bounded(-1.0, 1.0, (n_act,)), model_cfg)
    if a.init:
        policy.load_state_dict(ck["policy"])
    else:
        norm.update({k: fit[k] for k in OBS_KEYS})
    weights = mode_weight_vector(ck["config"]["optim"].get("mode_weights") if a.weighted else None)
    actor = policy.module[0].module
    optim = torch.optim.Adam(actor.parameters(), lr=a.lr)
    floor = a.lr_floor
    sched = torch.optim.lr_scheduler.LambdaLR(
        optim, lambda s: floor + (1 - floor) * 0.5 * (1 + math.cos(math.pi * min(s, a.steps) / a.steps)))

    @torch.no_grad()
    def evaluate(td) -> dict:
        errs = []
        for i in range(0, td.shape[0], 16384):
            b = td[i: i + 16384]
            loc, _ = actor(*(b[k] for k in OBS_KEYS))
            errs.append(((loc - b["expert_action"]) ** 2).mean(-1))
        return per_mode(torch.cat(errs), td["mode"])

    before = evaluate(test) if a.init else None
    t0 = time.perf_counter()
    for s in range(a.steps):
        b = fit[torch.randint(fit.shape[0], (a.batch_size,))]
        loc, _ = actor(*(b[k] for k in OBS_KEYS))
        loss, _ = distill_loss(loc, b["expert_action"], weights[b["mode"]], a.l1)
        optim.zero_grad(set_to_none=True)
        loss.backward()
        optim.step()
        sched.step()
        if (s + 1) % max(1, a.steps // 10) == 0:
            print(f"step {s + 1}: loss {float(loss.detach()):.5f} ({time.perf_counter() - t0:.0f} s)", flush=True)
    fitted, held = evaluate(fit), evaluate(test)
    label_var = {m: float(data["expert_action"][data["mode"] == i].var(0, unbiased=False).mean())
                 for i, m in enumerate(F.MODES) if bool((data["mode"] == i).any())}
    print(f"\n{a.run}: {n} samples ({n_test} held out), main_hidden {model_cfg.get('main_hidden', '(default)')}, "
          f"{a.steps} steps of {a.batch_size}\n")
    print("| mode | samples | label variance | MSE fitted | MSE held out |")
    print("|---|---|---|---|---|")
    counts = {m: int((data["mode"] == i).sum()) for i, m in enumerate(F.MODES)}
    for m in held:
        print(f"| {m} | {counts[m]} | {label_var[m]:.4f} | {fitted[m]:.5f} | {held[m]:.5f} |")
    if before is not None:
        print("\nheld out before the fit (the run's student): " + ", ".join(f"{m} {v:.2e}" for m, v in before.items()))
    if a.out:
        torch.save(dict(ck, policy=policy.state_dict()), a.out)
        print(f"wrote {a.out}")
    if a.json:
        Path(a.json).parent.mkdir(parents=True, exist_ok=True)
        Path(a.json).write_text(json.dumps(dict(
            run=str(a.run), relabel=relabel, samples=n, held_out=n_test, steps=a.steps, batch_size=a.batch_size, lr=a.lr,
            main_hidden=model_cfg.get("main_hidden"), seed=a.seed, seconds=time.perf_counter() - t0,
            label_variance=label_var, mse_fitted=fitted, mse_held_out=held, samples_per_mode=counts,
            init=a.init, weighted=a.weighted, lr_floor=a.lr_floor, mse_held_out_before=before), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
