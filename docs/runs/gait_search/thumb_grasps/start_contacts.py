"""Which fingers hold the object when an in-hand rotate trial starts, and does it decide the outcome? (diagnosis, 2026-11-27)

Runs the rotate protocol (``unicross eval --objects OBJS --limit L --trials-per-object 3 --seed 0``, one
process per shard) with POLICY (``zero`` or a gait spec) from the grasp-state dataset GRASPS (default: the
shipped one, the grasp expert's), records which contact links touch the object after the first control
step (net contact force > 1 mN) and prints successes and drops by the set of fingers in contact:

    python docs/runs/gait_search/thumb_grasps/start_contacts.py AXIS OBJS LIMIT POLICY [GRASPS] > out.txt
"""
import sys
from collections import Counter
from concurrent.futures import ProcessPoolExecutor

import torch

# Allegro's contact links in the order of configs/hands/allegro.yaml: palm, then 5 links per finger
FINGERS = {"palm": [0], "index": [1, 2, 3, 4, 5], "middle": [6, 7, 8, 9, 10], "ring": [11, 12, 13, 14, 15],
           "thumb": [16, 17, 18, 19, 20]}


def shard_trials(axis, objs, limit, spec, grasps, shard):
    torch.set_num_threads(1)
    import unicross  # noqa: F401
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    act = E.resolve_policy(spec, "allegro")[0]
    touching = []

    def policy(obs, u):
        if int(u.elapsed_steps[0]) == 1:  # the forces of the first control step (the reset reads none)
            f = u.link_force[0]
            touching.append(tuple(k for k, idx in FINGERS.items() if bool((f[idx] > 1e-3).any())))
        return act(obs, u)

    out = E.run_protocol("rotate", policy, get_object_set(objs, limit=limit), trials_per_object=3, seed=0,
                         axes=[axis], progress=False, shard=shard, grasp_dataset=grasps)
    return [dict(t, touching=k) for t, k in zip(out, touching)]


if __name__ == "__main__":
    axis, objs, limit, spec = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
    grasps = sys.argv[5] if len(sys.argv) > 5 else None
    with ProcessPoolExecutor(2) as ex:
        parts = list(ex.map(shard_trials, *zip(*[(axis, objs, limit, spec, grasps, (i, 2)) for i in range(2)])))
    trials = [t for p in parts for t in p]
    print(f"rotate {axis}, {objs} first {limit} per group x 3, policy {spec}, grasps {grasps or 'shipped'}: "
          f"n = {len(trials)}, {sum(t['success'] for t in trials)} successes, {sum(t['dropped'] for t in trials)} dropped")
    print("| fingers touching after step 1 | trials | successes | dropped |\n|---|---|---|---|")
    for key, n in Counter(t["touching"] for t in trials).most_common():
        sel = [t for t in trials if t["touching"] == key]
        print(f"| {' + '.join(key) or 'none'} | {n} | {sum(t['success'] for t in sel)} | {sum(t['dropped'] for t in sel)} |")
    for finger in FINGERS:
        print(f"{finger}: touching in {sum(finger in t['touching'] for t in trials)} of {len(trials)}")
