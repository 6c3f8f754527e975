"""Translate z- ratchets on training objects (README, "Two more finger motions"): the relay with one finger cycling.

Spec ``FINGER,H,L,R,C[,K]``: FINGER (index, middle or ring) curls its two distal joints at C rad per control step;
once its trigger joint's command reaches H it opens at R rad per step (its K most distal joints, 2 by default) until
that command is <= L, then curls again, and so on. The trigger joint is the finger's DIP (the ring's PIP: its DIP
starts at the limit). The other two fingers do what the relay does to them: the index curls at 0.1 from the first
step, the middle at 0.05 from the first step, the ring's two distal joints at 0.05 once the index's DIP command
reaches 0.9 rad. ``index,9,0,0.1,0.1`` (H never reached) is the relay itself.

Usage: python docs/runs/translate_zm_reference/ratchet.py "SPEC|SPEC|..." OBJECTS LIMIT TRIALS"""
import sys

import torch

import unicross  # noqa: F401  (registers the tasks)
from unicross import evaluation as E
from unicross.audit import finger_sweep_action
from unicross.objects import get_object_set
from unicross.sequences import make_sequence_policy

from finger_sequences import score_line  # this folder's scorer

torch.set_num_threads(1)
OTHERS = {"index": "ring:2:0.05:@index:0.9+middle:2:0.05:0:1000",
          "middle": "index:2:0.1:0:1000+ring:2:0.05:@index:0.9",
          "ring": "index:2:0.1:0:1000+middle:2:0.05:0:1000"}


def make(finger, H, L, R, C, K=2):
    rest = make_sequence_policy(OTHERS[finger])
    st = {}

    def pol(obs, u):
        if st.get("env") is not u:
            hs = u.hand_spec
            joint = hs.fingers[finger][-2 if finger == "ring" else -1]
            st.update(env=u, j=6 + hs.finger_joints.index(joint),
                      close=finger_sweep_action(hs, C, (finger, 2)).to(u.device),
                      open=finger_sweep_action(hs, -R, (finger, int(K))).to(u.device),
                      opening=torch.zeros(u.num_envs, 1, dtype=torch.bool))
        t = u.elapsed_steps[:, None]
        q = u.command[:, st["j"]][:, None]
        op = st["opening"] & (t != 0)  # a new episode starts curling
        op = torch.where(q >= H, torch.ones_like(op), torch.where(q <= L, torch.zeros_like(op), op))
        st["opening"] = op
        return (rest(obs, u) + torch.where(op, st["open"], st["close"])).clamp(-1, 1)
    return pol


def main() -> None:
    objs = get_object_set(sys.argv[2], limit=int(sys.argv[3]))
    for spec in sys.argv[1].split("|"):
        finger, *p = spec.split(",")
        trials = E.run_protocol("translate", make(finger, *[float(x) for x in p]), objs,
                                trials_per_object=int(sys.argv[4]), seed=0, axes=["z-"], progress=False)
        print(score_line(spec, trials, width=28), flush=True)


if __name__ == "__main__":
    main()
