"""Translate z-: the relay plus a wrist sawtooth along the hand's z from step S (period P, amplitude A of the
normalised wrist action, stroke toward the fingertips in one step, then a linear return). Usage: python docs/runs/translate_zm_reference/wrist_shake.py "S,P,A[,sign]|..." OBJECTS LIMIT TRIALS"""
import sys

import torch

import unicross  # noqa: F401  (registers the tasks)
from unicross import evaluation as E
from unicross.objects import get_object_set
from unicross.sequences import make_sequence_policy
from unicross.geometry import quat_apply

from finger_sequences import score_line  # this folder's scorer
torch.set_num_threads(1)
RELAY = "index:2:0.1:0:1000+ring:2:0.05:@index:0.9+middle:2:0.05:@ring:0.9"

def make(S, P, A, sign=1.0):
    relay = make_sequence_policy(RELAY)
    def pol(obs, u):
        a = relay(obs, u)
        t = u.elapsed_steps[:, None].float()
        ph = torch.remainder(t - S, P) / P  # 0 at the stroke, rising to 1
        saw = sign * (1.0 - 2.0 * ph) * A     # +A at the stroke step (toward fingertips), linear back to -A
        saw = torch.where(t >= S, saw, torch.zeros_like(saw))
        z = quat_apply(u.targets.q_hr, torch.tensor([0.0, 0.0, 1.0]).expand(u.num_envs, 3))
        a[:, :3] = saw * z
        return a.clamp(-1, 1)
    return pol

objs = get_object_set(sys.argv[2], limit=int(sys.argv[3]))
for spec in sys.argv[1].split("|"):
    p = [float(x) for x in spec.split(",")]
    trials = E.run_protocol("translate", make(*p), objs, trials_per_object=int(sys.argv[4]), seed=0, axes=["z-"], progress=False)
    print(score_line(spec, trials, width=20), flush=True)
