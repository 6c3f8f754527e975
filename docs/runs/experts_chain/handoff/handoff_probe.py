"""Who loses the student's translate z- after relocation: its grasp, its relocation or its in-hand action? (diagnosis,
2026-11-27)

The chain grasp -> relocate -> translate z- on the first LIMIT elongated test objects per group x 3 trials (seed 0, the
`unicross chain` protocol), each phase acted on by `student` (the shipped `allegro/student`) or `experts` (the shipped
per-mode experts, `experts:allegro`), in the translate phase `relay` (the finger sequence its expert imitates), or
`student_wrist` / `student_fingers` (the student's wrist action with the experts' finger action, or the reverse),
`experts_wrist_only` (the experts' wrist action, the fingers' commands held: zero finger action): GRASP, RELOCATE and TRANSLATE name who acts in each phase.

    python docs/runs/experts_chain/handoff/handoff_probe.py experts experts student 20 > docs/runs/experts_chain/handoff/E_E_S.txt
    python docs/runs/experts_chain/handoff/handoff_probe.py experts student experts 20 runs/student_x/checkpoint.pt   # another student
"""
import json
import sys

import torch

from unicross import formulation as F
from unicross.evaluation import resolve_policy, run_chain, summarize_chain
from unicross.objects import get_object_set

# the action's first 6 dims drive the wrist, the rest the fingers: one policy's wrist with the other's fingers
MIXED = {"student_wrist": ("student", "experts"), "student_fingers": ("experts", "student"),
         "experts_wrist_only": ("experts", "zero")}
SPECS = {"student": "allegro/student", "experts": "experts:allegro", "zero": "zero",
         # the scripted relay the shipped translate z- expert is a clone of (translate phase only)
         "relay": "seq:index:2:0.1:0:1000+ring:2:0.05:@index:0.9+middle:2:0.05:@ring:0.9"}

def phase_policies(roles):
    """mode index -> policy for the chain's grasp, relocate and translate z- phases, ``roles`` naming who acts in each
    (a key of SPECS or MIXED)."""
    loaded = {r: resolve_policy(SPECS[r], "allegro")[0] for r in set(roles) & set(SPECS)}
    for mixed, (wrist, fingers) in MIXED.items():
        if mixed in roles:
            w, f = (resolve_policy(SPECS[r], "allegro")[0] for r in (wrist, fingers))
            loaded[mixed] = lambda obs, u, w=w, f=f: torch.cat([w(obs, u)[:, :6], f(obs, u)[:, 6:]], -1)
    return {F.MODES.index(m): loaded[r] for m, r in zip(("grasp", "relocate", "translate_z-"), roles)}


if __name__ == "__main__":
    roles, limit = sys.argv[1:4], int(sys.argv[4])
    if len(sys.argv) > 5:  # another student checkpoint
        SPECS["student"] = sys.argv[5]
    by_mode = phase_policies(roles)

    def policy(obs, u):
        return by_mode[int(u.mode[0])](obs, u)

    trials = run_chain(policy, get_object_set("test-elongated", limit=limit), "grasp,relocate,translate:z-",
                       trials_per_object=3, seed=0, progress=False)
    s = summarize_chain(trials)["Gr. + Re. + Trans."]
    reached = [t for t in trials if t["phase_success"][0] and t["phase_success"][1]]
    print(json.dumps(dict(**{m: SPECS.get(r, r) for m, r in zip(("grasp", "relocate", "translate"), roles)}, n=s["n"],
                          phases=[round(p["sr"], 1) for p in s["phases"]],
                          overall=[round(s["overall"]["sr"], 1)] + [round(v, 1) for v in s["overall"]["ci95"]],
                          in_hand_after_relocation=f"{sum(t['phase_success'][2] for t in reached)} of {len(reached)}",
                          trials=[dict(object=t["object"], trial=t["trial"], phase_success=t["phase_success"],
                                       dropped_in_phase=t["dropped_in_phase"]) for t in trials]), indent=None))
