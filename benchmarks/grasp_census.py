"""Which fingers hold the objects of a grasp-state dataset: restore every grasp, hold it 2 s with the wrist
still (``unicross.scripted_grasp.hold_test``, as ``unicross grasps`` does before keeping a grasp) and count,
per object category, the fingers (and the palm) touching the object at the end, and the sets of them.

    python benchmarks/grasp_census.py configs/grasps/allegro.pt [--workers 2] [--write]

``--write`` adds the census to the dataset's sidecar (``FILE.json``: ``fingers_after_hold``, and
``fingers_after_hold_by`` with the command, the commit and how many grasps held); ``unicross grasps`` writes
``fingers_after_hold`` for the datasets it makes.
Objects are looked up in the train, test and unseen sets; one worker process per part of the objects.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _part(path: str, names: list, seed: int):
    import torch
    torch.set_num_threads(1)
    from unicross.grasps import GraspSet
    from unicross.objects import get_object_set
    from unicross.scripted_grasp import hold_test
    gs, wanted = GraspSet.load(path), set(names)
    objs = [o for s in ("train", "test", "unseen") for o in get_object_set(s) if o.name in wanted]
    held, touching = hold_test(gs.hand, gs, objs, seconds=2.0, seed=seed)
    return held, touching


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--write", action="store_true", help="add the census to the dataset's sidecar")
    args = ap.parse_args()
    from unicross.grasps import GraspSet
    from unicross.objects import get_object_set
    from unicross.rl.ppo import git_commit
    from unicross.scripted_grasp import finger_census
    gs = GraspSet.load(args.dataset)
    names = [n for n, c in gs.counts().items() if c > 0]
    parts = [names[i::args.workers] for i in range(args.workers)]
    t0 = time.time()
    with ProcessPoolExecutor(args.workers) as ex:
        results = list(ex.map(_part, [args.dataset] * len(parts), parts, [args.seed] * len(parts)))
    held = [any(r[0][i] for r in results) for i in range(len(gs))]  # each row is tested in one part
    touching = [next((r[1][i] for r in results if r[0][i]), ()) for i in range(len(gs))]
    objs = [o for s in ("train", "test", "unseen") for o in get_object_set(s)]
    census = finger_census(gs, objs, touching, rows=held)
    how = dict(command="python " + " ".join(sys.argv), commit=git_commit(), held=sum(held), grasps=len(gs),
               seconds=round(time.time() - t0, 1))
    print(json.dumps(dict(fingers_after_hold=census, fingers_after_hold_by=how), indent=1))
    if args.write:
        side = Path(str(args.dataset) + ".json")
        meta = json.loads(side.read_text()) if side.exists() else {}
        meta.update(fingers_after_hold=census, fingers_after_hold_by=how)
        side.write_text(json.dumps(meta, indent=1))


if __name__ == "__main__":
    main()
