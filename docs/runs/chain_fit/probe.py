"""How closely does each student follow its teachers on the translate chain's states, and does that track its
long-horizon Gr. + Re. + Trans. cell? (diagnosis, 2026-12-07, 66th session; informs, judges nothing)

The report's long-horizon trials (test objects, first 10 per group, 5 trials per object, seed 0: the trial seeds and
random directions of ``unicross chain``), the elongated ones (grasp -> relocate -> translate z+ / z-), acted on by the
shipped experts (each phase by its mode's expert). At every step the observation and the expert's action are kept;
then every student given is run on those observations, and the mean squared difference of its action to the
expert's (normalised actions; wrist dims 0-5 and finger dims apart) is reported per phase. The states are the
teachers', not the student's own: this measures the fitting error the student's own chain integrates (the
relocation's finger drift that spoils the translate phase, ``docs/runs/experts_chain/handoff/README.md``).

    python docs/runs/chain_fit/probe.py OBJECTS STATES.pt OUT.json STUDENT.pt [STUDENT.pt ...]

OBJECTS: the object set (``test``: the report's trials; ``train``: the same protocol on training objects, where a
recipe may be chosen). STATES.pt keeps the recorded states: made when missing, read when present.
"""
import os
import json
import sys

import gymnasium as gym
import torch

import unicross  # noqa: F401
from unicross import formulation as F
from unicross import registry as R
from unicross.evaluation import resolve_policy
from unicross.objects import get_object_set
from unicross.rl.policy_io import actor_action, load_policy, acting
from unicross.seeding import trial_seed
from unicross.tasks.chain import parse_sequence

EXPERTS = "experts:allegro"


def record(object_set):
    """The experts' translate chains: per step (observation tensors, expert action, mode), and the trial count."""
    experts, _ = resolve_policy(EXPERTS, "allegro")
    objects = get_object_set(object_set, limit=10)
    rng = torch.Generator().manual_seed(0)
    hand, obj, goal, act, mode = [], [], [], [], []
    n = 0
    for oi, o in enumerate(objects):
        for k in range(5):
            skill = "rotate" if o.category == "wrappable" else "translate"
            axes = R.skill(skill).axes
            axis = axes[int(torch.randint(len(axes), (1,), generator=rng))]  # drawn as run_chain draws it
            if skill != "translate":
                continue
            env = gym.make("UniCross-Chain-v1", obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none",
                           hand="allegro", objects=[o], randomize=False,
                           sequence=parse_sequence(f"grasp,relocate,translate:{axis}"))
            u = env.unwrapped
            obs, _ = u.reset(seed=trial_seed(0, oi, k))
            for t in range(u.phase_ends[-1]):
                a = experts(obs, u)
                ex = obs["extra"]
                hand.append(ex["hand"].clone())
                obj.append(torch.cat(list(ex["object"].values()), dim=-1).clone())
                goal.append(ex["goal"].clone())
                act.append(a.clone())
                mode.append(u.mode.clone())
                obs, _, term, _, _ = u.step(a)
                if bool(term.all()):
                    break
            env.close()
            n += 1
            print(f"trial {n}: {o.name} translate {axis}", file=sys.stderr, flush=True)
    cat = lambda xs: torch.cat(xs, 0)  # noqa: E731
    return dict(hand=cat(hand), obj=cat(obj), goal=cat(goal), act=cat(act), mode=cat(mode), n=n)


if __name__ == "__main__":
    object_set, states, out, students = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
    if not os.path.exists(states):
        torch.save(record(object_set), states)
    rec = torch.load(states)
    hand, obj, goal, act, mode, n = (rec[k] for k in ("hand", "obj", "goal", "act", "mode", "n"))
    res = dict(experts=EXPERTS, objects=object_set, trials=n, steps=int(len(act)), students={})
    for path in students:
        policy, _ = load_policy(path)
        net = acting(policy.module[0].module)
        with torch.no_grad():
            pred = actor_action(net, dict(extra=dict(hand=hand, object=dict(all=obj), goal=goal)))
        d = (pred - act) ** 2
        row = {}
        for m in ("grasp", "relocate", "translate_z+", "translate_z-"):
            sel = mode == F.MODES.index(m)
            row[m] = dict(steps=int(sel.sum()), wrist=float(d[sel, :6].mean()), fingers=float(d[sel, 6:].mean()))
        res["students"][path] = row
        print(path, json.dumps({m: (f"{v['wrist']:.2e}", f"{v['fingers']:.2e}") for m, v in row.items()}), flush=True)
    with open(out, "w") as f:
        json.dump(res, f, indent=1)
