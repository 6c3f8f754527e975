"""Does the student copy the rotate x+ expert's stop? Per step on the student's own x+ rollouts: the student's action,
the expert's action on the same observation (its label), and the finger command; summarised before and after the
expert's stop (the thumb's distal command past 0.5 rad, where the sequence it clones holds the fingers still).

    python docs/runs/student_xp_drift/drift.py POLICY OUT.json [--limit 5 --trials 2]

POLICY is what acts (a student checkpoint, or allegro/rotate_x+ itself); the labeller is allegro/rotate_x+ unless
`--labeller` names another x+ policy.
The rotate protocol's x+ trials (seeded as `unicross eval`) on `--objects` (test: held out; train: for choosing).
"""
import argparse
import json

import torch

import unicross.evaluation as E
from band import zero_small_finger_actions
from unicross.evaluation import protocol_objects, resolve_policy, run_protocol
from unicross.objects import get_object_set

p = argparse.ArgumentParser()
p.add_argument("policy")
p.add_argument("out")
p.add_argument("--limit", type=int, default=5)
p.add_argument("--trials", type=int, default=2)
p.add_argument("--objects", default="test", help="test (held out) or train (for choosing)")
p.add_argument("--seed", type=int, default=0)
p.add_argument("--labeller", default="allegro/rotate_x+", help="the policy whose action labels each step (default: the "
               "shipped x+ expert)")
p.add_argument("--bias-from", default=None, help="a drift.py output: add its trials' mean action error after the stop "
               "(16 finger joints, action units) to POLICY's action after the stop (a causal check: does that bias "
               "alone make the expert drop?)")
p.add_argument("--deadband", type=float, default=0.0, help="zero every finger action of POLICY smaller than this in "
               "magnitude (action units), at every step (a diagnostic: does removing small steady actions stop the "
               "drift, and what does it cost?)")
args = p.parse_args()

act_fn, _ = resolve_policy(args.policy, "allegro")
label_fn, _ = resolve_policy(args.labeller, "allegro")
THUMB_DIP = 6 + 15          # joint_15.0, the thumb's distal joint (the sequence's trigger)
FINGERS = slice(6, 22)
rows = []                   # per step of the current trial: (command[16], action[16], label[16])


bias = None
if args.bias_from:
    got = [t["bias_after"] for t in json.load(open(args.bias_from))["trials"] if t["bias_after"] is not None]
    bias = torch.tensor(got).mean(0)


def policy(obs, u):
    a = act_fn(obs, u)
    if args.deadband > 0:
        a = zero_small_finger_actions(a, args.deadband)
    if bias is not None and bool(u.command[0, THUMB_DIP] >= 0.5):
        a = a.clone()
        a[0, FINGERS] += bias.to(a)
    with torch.no_grad():
        b = label_fn(obs, u)
    rows.append((u.command[0, FINGERS].clone(), a[0, FINGERS].clone(), b[0, FINGERS].clone()))
    return a


per_trial = []
_score = E._score


def score(*a, **k):
    out = _score(*a, **k)
    cmd, act, lab = (torch.stack([r[i] for r in rows]) for i in range(3))
    after = cmd[:, THUMB_DIP - 6] >= 0.5  # the steps with the thumb's distal command past the stop
    t_stop = int(after.nonzero()[0]) if bool(after.any()) else None
    err = act - lab
    out.update(t_stop=t_stop, steps_after=int(after.sum()),
               mse_before=float((err[~after] ** 2).mean()) if bool((~after).any()) else None,
               mse_after=float((err[after] ** 2).mean()) if bool(after.any()) else None,
               bias_after=err[after].mean(0).tolist() if bool(after.any()) else None,
               drift_after=((cmd[-1] - cmd[t_stop]).tolist() if t_stop is not None else None),
               label_abs_after=float(lab[after].abs().mean()) if bool(after.any()) else None,
               label_wild_after=float((lab[after].abs().amax(-1) > 0.2).float().mean()) if bool(after.any()) else None,
               final_cmd=cmd[-1].tolist())
    rows.clear()
    per_trial.append(out)
    return out


E._score = score
# the report's x+ cell with limit=10, trials=3 (its first `limit` objects per group)
chosen, _ = protocol_objects("rotate", get_object_set(args.objects, limit=args.limit), "allegro")
run_protocol("rotate", policy, chosen, trials_per_object=args.trials, seed=args.seed, axes=["x+"], progress=False)
n = len(per_trial)
stopped = [t for t in per_trial if t["t_stop"] is not None]
summ = dict(policy=args.policy, labeller=args.labeller, bias_from=args.bias_from, deadband=args.deadband, objects=args.objects, limit=args.limit, trials=args.trials, seed=args.seed, n=n, successes=sum(t["success"] for t in per_trial),
            dropped=sum(t["dropped"] for t in per_trial), reached_stop=len(stopped),
            mean_t_stop=sum(t["t_stop"] for t in stopped) / max(1, len(stopped)),
            mse_before=sum(t["mse_before"] for t in per_trial if t["mse_before"] is not None) / n,
            mse_after=(sum(t["mse_after"] for t in stopped) / len(stopped)) if stopped else None,
            mean_abs_drift_after=(sum(sum(abs(x) for x in t["drift_after"]) / 16 for t in stopped) / len(stopped)) if stopped else None,
            success_if_stopped=sum(t["success"] for t in stopped), dropped_if_stopped=sum(t["dropped"] for t in stopped))
json.dump(dict(summary=summ, trials=per_trial), open(args.out, "w"), indent=1)
print(json.dumps(summ, indent=1))
