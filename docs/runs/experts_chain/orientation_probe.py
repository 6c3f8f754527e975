"""Rotate protocol (held-out test cell: first LIMIT per group x 3, seed 0) from the grasp dataset with the wrist
orientation drawn as: random (the protocol), palm_up (--original), palm_down (palm normal down, random yaw, as the
grasp expert leaves the hand). A diagnosis: palm_down replaces the sampler of random orientations in this process.

    python docs/runs/experts_chain/orientation_probe.py POLICY AXIS LIMIT random|palm_up|palm_down
"""
import math
import sys

import torch

import unicross  # noqa: F401  (registers the tasks)
from unicross import evaluation as E
from unicross.objects import get_object_set
import unicross.tasks.starts as S
from unicross.geometry import quat_from_matrix
torch.set_num_threads(1)
spec, axis, limit, orient = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
if orient == "palm_down":
    def palm_down(n, gen, device):
        psi = torch.rand(n, generator=gen, device=device) * 2 * math.pi
        xd = torch.tensor([0.0, 0.0, -1.0], device=device).expand(n, 3)
        zd = torch.stack([torch.cos(psi), torch.sin(psi), torch.zeros_like(psi)], -1)
        return quat_from_matrix(torch.stack([xd, torch.cross(zd, xd, dim=-1), zd], dim=-1))
    S._random_quaternion = palm_down
policy, desc = E.resolve_policy(spec, "allegro")
trials = E.run_protocol("rotate", policy, get_object_set("test", limit=limit), trials_per_object=3, seed=0, axes=[axis],
                        progress=False, original=(orient == "palm_up"))
n, ok = len(trials), sum(t["success"] for t in trials)
print(spec, axis, orient, f"{ok}/{n} = {100 * ok / n:.1f}%, dropped {sum(t['dropped'] for t in trials)}", flush=True)
