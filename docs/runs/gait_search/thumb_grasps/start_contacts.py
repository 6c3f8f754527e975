"""Which fingers hold the object when an in-hand trial starts, and does it decide the outcome? (diagnosis, 2026-11-27)

Runs the rotate (or, with ``--translate``, the translate) protocol (``unicross eval --objects OBJS --limit L --trials-per-object 3 --seed 0``, one
process per shard) with POLICY (``zero`` or a gait spec) from the grasp-state dataset GRASPS (default: the
shipped one, the grasp expert's), records which contact links touch the object after the first control
step (net contact force > 1 mN) and prints successes and drops by the set of fingers in contact:

    python docs/runs/gait_search/thumb_grasps/start_contacts.py [--translate] AXIS OBJS LIMIT POLICY [GRASPS] > out.txt
"""
import sys
from collections import Counter
from concurrent.futures import ProcessPoolExecutor

import torch


def shard_trials(protocol, axis, objs, limit, spec, grasps, shard):
    torch.set_num_threads(1)
    import unicross  # noqa: F401
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    from unicross.scripted_grasp import contact_link_fingers, fingers_touching
    act = E.resolve_policy(spec, "allegro")[0]
    touching = []

    def policy(obs, u):
        if int(u.elapsed_steps[0]) == 1:  # the forces of the first control step (the reset reads none)
            touching.append(fingers_touching(u, contact_link_fingers(u)))
        return act(obs, u)

    out = E.run_protocol(protocol, policy, get_object_set(objs, limit=limit), trials_per_object=3, seed=0,
                         axes=[axis], progress=False, shard=shard, grasp_dataset=grasps)
    return [dict(t, touching=k) for t, k in zip(out, touching)]


if __name__ == "__main__":
    args = sys.argv[1:]
    protocol = "translate" if args[:1] == ["--translate"] else "rotate"
    args = args[1:] if protocol == "translate" else args
    axis, objs, limit, spec = args[0], args[1], int(args[2]), args[3]
    grasps = args[4] if len(args) > 4 else None
    with ProcessPoolExecutor(2) as ex:
        parts = list(ex.map(shard_trials, *zip(*[(protocol, axis, objs, limit, spec, grasps, (i, 2)) for i in range(2)])))
    trials = [t for p in parts for t in p]
    print(f"{protocol} {axis}, {objs} first {limit} per group x 3, policy {spec}, grasps {grasps or 'shipped'}: "
          f"n = {len(trials)}, {sum(t['success'] for t in trials)} successes, {sum(t['dropped'] for t in trials)} dropped")
    print("| fingers touching after step 1 | trials | successes | dropped |\n|---|---|---|---|")
    for key, n in Counter(t["touching"] for t in trials).most_common():
        sel = [t for t in trials if t["touching"] == key]
        print(f"| {' + '.join(key) or 'none'} | {n} | {sum(t['success'] for t in sel)} | {sum(t['dropped'] for t in sel)} |")
    for finger in ("palm", "index", "middle", "ring", "thumb"):
        print(f"{finger}: touching in {sum(finger in t['touching'] for t in trials)} of {len(trials)}")
