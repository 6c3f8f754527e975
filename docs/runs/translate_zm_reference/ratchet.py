"""Translate z- ratchet (training objects; see README, "Two more finger motions"): the relay's middle and ring
terms, and an index that curls at 0.1 rad per step; once the index's distal command reaches H the index opens at rate R
until its distal command is <= L, then closes again at 0.1 (repeat). Usage: python docs/runs/translate_zm_reference/ratchet.py "H,L,R[,k]|..." (k: the index joints that open, 2 by default) OBJECTS LIMIT TRIALS"""
import sys

import torch

import unicross  # noqa: F401  (registers the tasks)
from unicross import evaluation as E
from unicross.objects import get_object_set
from unicross.sequences import make_sequence_policy
from unicross.audit import finger_sweep_action
torch.set_num_threads(1)
RELAY = "ring:2:0.05:@index:0.9+middle:2:0.05:@ring:0.9"

def make(H, L, R, k_open=2):
    rest = make_sequence_policy(RELAY)
    st = {}
    def pol(obs, u):
        if st.get("env") is not u:
            hs = u.hand_spec
            st.update(env=u, j=6 + hs.finger_joints.index(hs.fingers["index"][-1]),
                      close=finger_sweep_action(hs, 0.1, ("index", 2)).to(u.device),
                      open=finger_sweep_action(hs, -R, ("index", k_open)).to(u.device),
                      opening=torch.zeros(u.num_envs, 1, dtype=torch.bool))
        t = u.elapsed_steps[:, None]
        q = u.command[:, st["j"]][:, None]
        op = st["opening"] & (t != 0)
        op = torch.where(q >= H, torch.ones_like(op), torch.where(q <= L, torch.zeros_like(op), op))
        st["opening"] = op
        a = rest(obs, u) + torch.where(op, st["open"], st["close"])
        return a.clamp(-1, 1)
    return pol

objs = get_object_set(sys.argv[2], limit=int(sys.argv[3]))
for spec in sys.argv[1].split("|"):
    p = [float(x) for x in spec.split(",")]
    trials = E.run_protocol("translate", make(p[0], p[1], p[2], int(p[3]) if len(p) > 3 else 2), objs,
                            trials_per_object=int(sys.argv[4]), seed=0, axes=["z-"], progress=False)
    n, ok = len(trials), sum(t["success"] for t in trials)
    drops = sum(t["dropped"] for t in trials)
    by = {}
    for t in trials:
        by.setdefault(t["object"].split("-")[1], []).append(t["success"])
    print(f"{spec:20s} success {ok}/{n} ({100*ok/n:.1f}%), drops {drops}; " + ", ".join(f"{k} {sum(v)}/{len(v)}" for k, v in sorted(by.items())), flush=True)
