"""What the chain hands to translate z-: the fingers on the stick, their commands, the stick's place in the hand
(diagnosis, 2026-11-27)

The chain grasp -> relocate -> translate z- as in `handoff_probe.py` (first LIMIT elongated test objects per group x 3
trials, seed 0, the `unicross chain` trial seeds): GRASP and RELOCATE name who acts in those phases (`student` or
`experts`), the translate phase is acted on by the shipped experts. Recorded per trial: at the first translate step, the
fingers pressing on the stick (`unicross.scripted_grasp.fingers_touching`), the stick's position and long axis in the
hand, the hand's z against the world's up; over the relocate phase, how far each finger's joint commands moved (sum of
|change| over its joints, rad) and, at its end, how far each finger's commands lead its joints (sum of command - joint
position, rad: the PD squeeze); then the translate phase's outcome. Prints the in-hand success by finger set, and the
medians of the commands' motion and lead by outcome:

    python docs/runs/experts_chain/handoff/handoff_fingers.py experts student 20 > docs/runs/experts_chain/handoff/fingers_E_student.txt
"""
import collections
import json
import sys

import gymnasium as gym
import torch

import unicross  # noqa: F401
from unicross import formulation as F
from unicross.evaluation import trial_seed
from unicross.geometry import quat_apply
from unicross.objects import get_object_set
from unicross.scripted_grasp import contact_link_fingers, fingers_touching

from handoff_probe import SPECS, phase_policies  # this folder's probe (the script's folder is on sys.path)

EX, EZ = torch.tensor([1.0, 0.0, 0.0]), torch.tensor([0.0, 0.0, 1.0])
FINGERS = ("index", "middle", "ring", "thumb")


def med(v):
    return sorted(v)[len(v) // 2] if v else float("nan")


if __name__ == "__main__":
    roles, limit = sys.argv[1:3], int(sys.argv[3])
    by_mode = phase_policies(roles + ["experts"])
    relocate, translate = F.MODES.index("relocate"), F.MODES.index("translate_z-")
    rows = []
    for oi, obj in enumerate(get_object_set("test-elongated", limit=limit)):
        for k in range(3):
            env = gym.make("UniCross-Chain-v1", obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none",
                           hand="allegro", objects=[obj], randomize=False, sequence="grasp,relocate,translate:z-")
            u = env.unwrapped
            hs = u.hand_spec
            fingers = contact_link_fingers(u)
            cols = {f: [hs.finger_joints.index(j) for j in hs.fingers[f]] for f in FINGERS}  # the command's finger order
            obs, info = u.reset(seed=trial_seed(0, oi, k))
            at_handoff, cmd_start = None, None
            for t in range(u.phase_ends[-1]):
                mode = int(u.mode[0])
                if mode == relocate and cmd_start is None:
                    cmd_start = u.command[0, 6:].clone()
                if mode == translate and at_handoff is None:
                    cmd = u.command[0, 6:]
                    lead = cmd - u.agent.robot.get_qpos()[0, u._qidx][6:]  # joint positions in the hand's order
                    at_handoff = dict(
                        fingers="+".join(fingers_touching(u, fingers)) or "none",
                        moved={f: round(float((cmd - cmd_start)[c].abs().sum()), 3) for f, c in cols.items()},
                        lead={f: round(float(lead[c].sum()), 3) for f, c in cols.items()},
                        x_oh=[round(v, 4) for v in u.prev_rel.x_oh[0].tolist()],
                        axis_z=round(abs(float(quat_apply(u.prev_rel.q_oh[0], EX)[2])), 3),
                        hand_z_up=round(float(quat_apply(u.root_q[0], EZ)[2]), 3))
                obs, _, term, trunc, info = u.step(by_mode[mode](obs, u))
                if bool(term.all()):
                    break
            ps = u.phase_success[0].tolist()
            if ps[0] and ps[1]:
                rows.append(dict(object=obj.name, shape=obj.shape, trial=k, success=bool(ps[2]), **at_handoff))
            env.close()
    print(f"grasp by {SPECS[roles[0]]}, relocate by {SPECS[roles[1]]}, translate z- by the experts: "
          f"{len(rows)} trials reached translate, {sum(r['success'] for r in rows)} succeeded")
    by = collections.defaultdict(lambda: [0, 0])
    for r in rows:
        by[r["fingers"]][0] += r["success"]
        by[r["fingers"]][1] += 1
    for f, (s, n) in sorted(by.items(), key=lambda kv: -kv[1][1]):
        print(f"  {f}: {s} of {n}")
    for ok in (True, False):
        sel = [r for r in rows if r["success"] == ok]
        print(f"{'succeeded' if ok else 'failed'} ({len(sel)}): commands moved in relocation, median rad: "
              + ", ".join(f"{f} {med([r['moved'][f] for r in sel]):.3f}" for f in FINGERS)
              + "; commands' lead over the joints: " + ", ".join(f"{f} {med([r['lead'][f] for r in sel]):.3f}" for f in FINGERS)
              + f"; stick in the hand x/y/z {[round(med([r['x_oh'][i] for r in sel]), 3) for i in range(3)]}"
              + f"; |stick axis . hand z| {med([r['axis_z'] for r in sel]):.3f}; hand z . up {med([r['hand_z_up'] for r in sel]):.2f}")
    print(json.dumps(rows))
