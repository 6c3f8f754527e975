"""Relay successes on the 120 training starts by shape, length band and whether the middle finger touches the stick
after the first step (diagnosis, 2026-11-27; README "Which fingers hold the stick at the start"):

    python docs/runs/translate_zm_reference/start_contacts/by_shape.py > by_shape.txt
"""
import os
import sys
from concurrent.futures import ProcessPoolExecutor

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "gait_search", "thumb_grasps"))
from start_contacts import shard_trials  # noqa: E402

RELAY = "seq:index:2:0.1:0:1000+ring:2:0.05:@index:0.9+middle:2:0.05:@ring:0.9"

if __name__ == "__main__":
    from unicross.objects import get_object_set
    with ProcessPoolExecutor(2) as ex:
        parts = list(ex.map(shard_trials, *zip(*[("translate", "z-", "train", 20, RELAY, None, (i, 2)) for i in range(2)])))
    trials = [t for p in parts for t in p]
    length = {o.name: o.dims[0] for o in get_object_set("train", limit=20)}
    print("| shape | length (m) | trials | successes | middle on: trials, successes | middle off: trials, successes |")
    print("|---|---|---|---|---|---|")
    for shape in ("box", "cylinder"):
        for lo, hi in ((0.0, 0.7), (0.7, 0.75), (0.75, 0.9)):
            sel = [t for t in trials if t["shape"] == shape and lo <= length[t["object"]] < hi]
            on = [t for t in sel if "middle" in t["touching"]]
            off = [t for t in sel if "middle" not in t["touching"]]
            print(f"| {shape} | {lo}-{hi} | {len(sel)} | {sum(t['success'] for t in sel)} | {len(on)}, "
                  f"{sum(t['success'] for t in on)} | {len(off)}, {sum(t['success'] for t in off)} |")
