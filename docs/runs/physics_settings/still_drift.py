"""How far a held object creeps in a still hand: the zero action on the rotate protocol (the fingers hold
their grasp command, the wrist stays), per solver iteration count. A probe, not a protocol.

    python docs/runs/physics_settings/still_drift.py AXIS LIMIT TRIALS ITERATIONS [ITERATIONS ...]

For each iteration count: the grasp-state starts of the rotate protocol on the first LIMIT training
objects per group x TRIALS (the evaluation's seeds), the zero action for the protocol's 400 steps; prints
drops and the object's displacement in the hand frame (from its start) after 50, 200 and 400 steps, over
the trials that still hold it. Nothing moves the object but gravity and the solver.
"""
import json
import statistics
import sys

import torch


def main():
    axis, limit, trials = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    torch.set_num_threads(1)
    from unicross.evaluation import run_protocol, zero_policy
    from unicross.objects import get_object_set
    out = {}
    for it in map(int, sys.argv[4:]):
        track = []

        def policy(obs, u):
            if int(u.elapsed_steps[0]) == 0:
                track.append([])
            track[-1].append(u.cur_rel.x_oh[0].clone())
            return zero_policy(obs, u)
        rows = run_protocol("rotate", policy, get_object_set("train", limit=limit), axes=[axis], trials_per_object=trials,
                            seed=0, progress=False, sim=dict(solver_position_iterations=it))
        res = dict(n=len(rows), dropped=sum(r["dropped"] for r in rows))
        for t in (50, 200, 399):
            d = [float((tr[t] - tr[0]).norm()) * 100 for tr, r in zip(track, rows) if len(tr) > t and not r["dropped"]]
            res[f"drift_cm_{t + 1}"] = dict(median=round(statistics.median(d), 2), mean=round(statistics.mean(d), 2),
                                           held=len(d)) if d else None
        out[it] = res
        print(f"iterations {it}: {json.dumps(res)}", flush=True)


if __name__ == "__main__":
    main()
