"""How far one PPO update moves the policy, per minibatch step and through the observation
statistics, at a given learning rate and exploration noise.

Runs ``unicross train``'s trainer for a few iterations (2 env workers, 1 object per group, no
evaluations) and prints, per iteration: the approximate KL of every minibatch step (ClipPPOLoss's
``kl_approx``; the first is 0 when collection and update see the same policy), and the KL and ratio
clip fraction of the whole batch after the update, which also includes the observation-statistics
update that follows it (outside PPO's trust region).

    python benchmarks/ppo_kl_probe.py [--skill relocate] [--lr 1e-6] [--log-std -3.0] [--iterations 4]
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile

import torch

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from unicross.rl.algorithm import PPO  # noqa: E402
from unicross.rl.models import OBS_KEYS  # noqa: E402
from unicross.rl.ppo import PPOTrainer  # noqa: E402


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--skill", default="relocate")
    p.add_argument("--lr", type=float, default=1e-6)
    p.add_argument("--log-std", type=float, default=-3.0)
    p.add_argument("--iterations", type=int, default=4)
    args = p.parse_args()
    update, schedule = PPO.update, PPO._schedule_lr

    def probed_update(self, data):
        self._kls = []
        with torch.no_grad():
            obs = data.select(*OBS_KEYS).clone()
            loc0 = self.policy.module[0](obs.clone())["loc"].clone()
        out = update(self, data)
        with torch.no_grad():
            after = self.policy.get_dist(obs).log_prob(data["action"])
            ratio = (after - data["action_log_prob"]).exp()
            moved = (self.policy.module[0](obs.clone())["loc"] - loc0).abs().mean(0)
            scale = data["scale"].mean(0)
        self._updates = getattr(self, "_updates", 0) + 1
        print(f"update {self._updates}: minibatch KL {[round(k, 4) for k in self._kls]}")
        print(f"  action mean moved by {float(moved.mean()):.2e} on average over the batch "
              f"({float((moved / scale).mean()):.2f} sigma)")
        print(f"  whole batch after the update and the statistics update: KL "
              f"{float((data['action_log_prob'] - after).mean()):.4f}, "
              f"|ratio - 1| > 0.2 for {float(((ratio - 1).abs() > 0.2).float().mean()):.2f}", flush=True)
        return out

    def probed_schedule(self, kl):
        self._kls.append(kl)
        return schedule(self, kl)

    PPO.update, PPO._schedule_lr = probed_update, probed_schedule
    overrides = {"env": {"num_envs": 2, "object_limit": 1}, "logging": {"eval_trials": 0, "final_eval_trials": 0},
                 "collector": {"total_frames": 1024 * args.iterations},
                 "optim": {"lr": args.lr, "lr_min": args.lr}, "model": {"init_log_std": args.log_std}}
    trainer = PPOTrainer(tempfile.mkdtemp(), skill=args.skill, overrides=overrides, progress=False)
    print(f"{args.skill}: lr {args.lr:g} (fixed by the floor), exploration sigma {torch.exp(torch.tensor(args.log_std)):.3f}")
    trainer.train(eval_at_ends=False)


if __name__ == "__main__":
    main()
