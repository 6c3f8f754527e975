"""Where does the student lose translate z+ on the unseen prisms? Its action error against its teacher on its own
states, test objects against unseen ones.

    python docs/runs/student10_relay_s0_ft/unseen/action_error.py [--student allegro/student]
        [--teacher allegro/translate_z+] [--axis z+] [--limit 40] [--trials 3] [--json out.json]

The student acts (the translate protocol, ``run_protocol``: first ``limit`` elongated objects of each set, ``trials``
seeded trials each, one process); at every step the teacher's deterministic action on the same observation is
computed too (the label DAgger would give), and the squared error is kept per step, split into the wrist (6) and the
finger dims. Printed per set: success, the mean squared error over all steps, over the first 10 steps, and over the
steps of failed and successful trials. The teacher acting alone on the same trials is the expert's own rate.
"""
import argparse
import json
from pathlib import Path

import torch

from unicross.evaluation import resolve_policy, run_protocol
from unicross.objects import get_object_set


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--student", default="allegro/student")
    p.add_argument("--teacher", default="allegro/translate_z+")
    p.add_argument("--axis", default="z+")
    p.add_argument("--limit", type=int, default=40)
    p.add_argument("--trials", type=int, default=3)
    p.add_argument("--json", default=None)
    args = p.parse_args()
    torch.set_num_threads(1)
    student, _ = resolve_policy(args.student, "allegro")
    teacher, _ = resolve_policy(args.teacher, "allegro")
    out = {}
    for objects in ("test", "unseen"):
        objs = [o for o in get_object_set(objects) if o.category == "elongated"][:args.limit]
        errs, episode = [], []

        def acting(obs, u):
            a = student(obs, u)
            b = teacher(obs, u).clamp(-1.0, 1.0)
            episode.append(((a - b) ** 2)[0])
            return a

        trials = run_protocol("translate", acting, objs, trials_per_object=args.trials, seed=0, axes=[args.axis],
                              progress=False)
        # run_protocol calls the policy once per step of each trial in order: split the steps by trial length
        i = 0
        for t in trials:
            n = t["steps"]
            errs.append(torch.stack(episode[i:i + n]))
            i += n
        assert i == len(episode), (i, len(episode))
        alone = run_protocol("translate", teacher, objs, trials_per_object=args.trials, seed=0, axes=[args.axis],
                             progress=False)
        ok = torch.tensor([t["success"] for t in trials])
        allsteps = torch.cat(errs)

        def mse(x):
            return dict(all=round(float(x.mean()), 5), wrist=round(float(x[:, :6].mean()), 5),
                        fingers=round(float(x[:, 6:].mean()), 5))

        row = dict(n=len(trials), student_sr=round(100 * float(ok.float().mean()), 1),
                   teacher_sr=round(100 * sum(t["success"] for t in alone) / len(alone), 1),
                   student_dropped=sum(t["dropped"] for t in trials),
                   mse_all_steps=mse(allsteps), mse_first10=mse(torch.cat([e[:10] for e in errs])),
                   mse_failed_trials=mse(torch.cat([e for e, s in zip(errs, ok) if not s])) if (~ok).any() else None,
                   mse_successful_trials=mse(torch.cat([e for e, s in zip(errs, ok) if s])) if ok.any() else None)
        out[objects] = row
        print(objects, json.dumps(row), flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(dict(args=vars(args), sets=out), indent=1) + "\n")


if __name__ == "__main__":
    main()
