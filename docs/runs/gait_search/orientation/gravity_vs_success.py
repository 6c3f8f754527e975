"""Does a shipped rotate gait's success depend on how the hand is oriented? (diagnosis, 2026-11-26)

The rotate protocol starts every trial in a random wrist orientation (the paper's), and the gaits are
open loop with the wrist held still. For each trial this records gravity's direction in the hand frame
at the start (x_h: palm normal, z_h: towards the fingertips) and the outcome, on the objects and trials
of ``unicross eval --objects OBJS --limit L --trials-per-object 3 --seed 0`` (one process per shard):

    python docs/runs/gait_search/orientation/gravity_vs_success.py AXIS OBJS LIMIT > out.json
"""
import json
import sys
from concurrent.futures import ProcessPoolExecutor

import torch


def shard_trials(axis, objs, limit, shard):
    torch.set_num_threads(1)
    import unicross  # noqa: F401
    from unicross import evaluation as E
    from unicross.gaits import make_gait_policy
    from unicross.geometry import quat_apply, quat_inv
    from unicross.objects import get_object_set
    gait = make_gait_policy(f"allegro/rotate_{axis}")
    grav = []

    def policy(obs, u):
        if int(u.elapsed_steps[0]) == 0:  # gravity (world -z) in the hand's start frame
            g = torch.tensor([[0.0, 0.0, -1.0]]).expand(u.num_envs, 3)
            grav.append(quat_apply(quat_inv(u.root_q), g)[0].tolist())
        return gait(obs, u)

    out = E.run_protocol("rotate", policy, get_object_set(objs, limit=limit), trials_per_object=3, seed=0,
                         axes=[axis], progress=False, shard=shard)
    return [dict(t, gravity_h=g) for t, g in zip(out, grav)]


if __name__ == "__main__":
    axis, objs, limit = sys.argv[1], sys.argv[2], int(sys.argv[3])
    with ProcessPoolExecutor(2) as ex:
        parts = list(ex.map(shard_trials, [axis] * 2, [objs] * 2, [limit] * 2, [(0, 2), (1, 2)]))
    trials = [t for p in parts for t in p]
    rows = []
    for name, k in (("x_h (palm normal)", 0), ("y_h", 1), ("z_h (fingertips)", 2)):
        for lo, hi in ((-1.01, -0.5), (-0.5, 0.5), (0.5, 1.01)):
            sel = [t for t in trials if lo <= t["gravity_h"][k] < hi]
            rows.append(dict(component=name, range=[lo, hi], n=len(sel),
                             success=sum(t["success"] for t in sel), dropped=sum(t["dropped"] for t in sel)))
    json.dump(dict(axis=axis, objects=objs, limit=limit, n=len(trials), successes=sum(t["success"] for t in trials),
                   by_gravity=rows, trials=trials), sys.stdout, indent=1)
