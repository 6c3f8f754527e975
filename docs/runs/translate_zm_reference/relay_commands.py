"""The relay's joint commands: medians over 120 translate z- episodes (training objects, first 20 per group x 3) of the
index, middle and ring fingers' PIP and DIP commands at control steps 0, 10, 30 and 49.
Usage: python docs/runs/translate_zm_reference/relay_commands.py"""
import torch

import unicross  # noqa: F401  (registers the tasks)
from unicross import evaluation as E
from unicross.objects import get_object_set
from unicross.sequences import make_sequence_policy
torch.set_num_threads(1)
base = make_sequence_policy("index:2:0.1:0:1000+ring:2:0.05:@index:0.9+middle:2:0.05:@ring:0.9")
rows = {0: [], 10: [], 30: [], 49: []}
def pol(obs, u):
    hs = u.hand_spec
    t = int(u.elapsed_steps[0])
    if t in rows:
        rows[t].append([float(u.command[0, 6 + hs.finger_joints.index(j)]) for f in ("index", "middle", "ring") for j in hs.fingers[f][-2:]])
    return base(obs, u)
E.run_protocol("translate", pol, get_object_set("train", limit=20), trials_per_object=3, seed=0, axes=["z-"], progress=False)
import numpy as np
for t, r in rows.items():
    r = np.array(r); print(t, len(r), "median [index PIP, DIP, middle PIP, DIP, ring PIP, DIP]:", np.round(np.median(r, 0), 3).tolist(), "min ring PIP", round(r[:, 4].min(), 3))
