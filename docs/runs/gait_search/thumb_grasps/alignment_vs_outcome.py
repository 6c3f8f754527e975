"""Does a rotate gait do better when the start's index-ring pinch lies closer to the hand's y axis? (diagnosis, 2026-11-27)

The shipped gait of AXIS on the rotate protocol's training starts (first 20 objects per group x 3, seed 0); per
trial the index-to-ring contact direction after the first control step (``pinch_axis.py``'s measure) and the
outcome; trials split into thirds by |y| of that direction:

    python docs/runs/gait_search/thumb_grasps/alignment_vs_outcome.py y- > alignment_y-.txt
"""
import os
import sys
from concurrent.futures import ProcessPoolExecutor

import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # pinch_axis.py beside this file


def shard_trials(axis, shard):
    torch.set_num_threads(1)
    import unicross  # noqa: F401
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    from pinch_axis import pinch_direction
    act = E.resolve_policy(f"gait:allegro/rotate_{axis}", "allegro")[0]
    pinch = []

    def policy(obs, u):
        if int(u.elapsed_steps[0]) == 1:
            d = pinch_direction(u, "index", "ring")
            pinch.append(None if d is None else d.tolist())
        return act(obs, u)

    out = E.run_protocol("rotate", policy, get_object_set("train", limit=20), trials_per_object=3, seed=0,
                         axes=[axis], progress=False, shard=shard)
    return [dict(t, pinch=p) for t, p in zip(out, pinch)]


if __name__ == "__main__":
    axis = sys.argv[1]
    with ProcessPoolExecutor(2) as ex:
        parts = list(ex.map(shard_trials, [axis] * 2, [(0, 2), (1, 2)]))
    trials = sorted((t for p in parts for t in p if t["pinch"] is not None), key=lambda t: abs(t["pinch"][1]))
    q = len(trials) // 3
    print(f"gait rotate {axis}, training starts with index and ring on the object: {len(trials)}")
    print("| third by pinch alignment | abs(y) | trials | successes | dropped |\n|---|---|---|---|---|")
    for name, sel in (("least aligned", trials[:q]), ("middle", trials[q:2 * q]), ("most aligned", trials[2 * q:])):
        ys = [abs(t["pinch"][1]) for t in sel]
        print(f"| {name} | {min(ys):.3f}-{max(ys):.3f} | {len(sel)} | {sum(t['success'] for t in sel)} | "
              f"{sum(t['dropped'] for t in sel)} |")
