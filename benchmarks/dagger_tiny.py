"""A real, tiny DAgger run on the CPU: ten 16-frame PPO experts, then the student.

Prints, per mode, the student's action MSE to the experts on held-out states before and after
distillation, and the success rates seen in rollouts (experts: their PPO training episodes;
student: its DAgger rollouts). At this scale the experts are untrained, so success rates are 0:
this checks the machinery, not the paper's numbers.

    python benchmarks/dagger_tiny.py
"""
from __future__ import annotations

import csv
import json
import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests"))
from test_dagger import SHORT, _held_out  # noqa: E402

from unicross import formulation as F  # noqa: E402
from unicross.rl.dagger import DAggerTrainer  # noqa: E402
from unicross.rl.ppo import PPOTrainer  # noqa: E402


def main():
    root = Path(tempfile.mkdtemp())
    expert_success = {}
    for mode in F.MODES:
        skill = F.mode_skill(mode)
        axis = mode.split("_")[1] if "_" in mode else None
        t = PPOTrainer(root / "experts" / mode, skill, axis, progress=False, overrides=dict(
            env=dict(num_envs=1, object_limit=1, reconfiguration_freq=0),
            collector=dict(total_frames=16, horizon=16), optim=dict(minibatch_size=16, mini_epochs=1),
            logging=dict(eval_trials=0, final_eval_trials=0)))
        t.train(eval_at_ends=False)
        t.close()
        rows = list(csv.DictReader(open(root / "experts" / mode / "metrics.csv")))
        vals = [float(r["success_rate"]) for r in rows if r["success_rate"]]
        expert_success[mode] = sum(vals) / len(vals) if vals else None
    cfg = dict(env=dict(num_envs=1, object_limit=1, reconfiguration_freq=1, randomize=False,
                        task_config=dict(episode_length=SHORT)),
               collector=dict(rollout_steps=8), optim=dict(batch_size=64, grad_steps=20, epochs=26, lr=1e-3),
               buffer=dict(capacity=5000), logging=dict(checkpoint_every=100))
    t = DAggerTrainer(root / "student", root / "experts", overrides=cfg, progress=False)
    held = _held_out()
    before = t.action_mse(held)
    t.train()
    after = t.action_mse(held)
    t.close()
    student_success = {}
    for line in open(root / "student" / "metrics.jsonl"):
        for k, v in json.loads(line).items():
            if k.startswith("success/"):
                student_success.setdefault(k[8:], []).append(v)
    print(f"{'mode':14s} {'MSE before':>10s} {'MSE after':>10s} {'expert SR':>10s} {'student SR':>10s}")
    for m in F.MODES:
        es = expert_success.get(m)
        ss = student_success.get(m)
        print(f"{m:14s} {before[m]:10.4f} {after[m]:10.4f} {('%.2f' % es) if es is not None else '--':>10s} "
              f"{('%.2f' % (sum(ss) / len(ss))) if ss else '--':>10s}")


if __name__ == "__main__":
    main()
