"""Does a firmer grip beat the zero action on relocation? A diagnosis, not an expert.

The zero action beats the shipped relocate expert on the paper's full test protocol, disturbed and not
(docs/record/full_protocol.md, last section); most of the zero action's failures are drops. This runs the policy
"wrist residual zero, fingers closed by TIGHTEN rad": towards the grasp pose (``tightened_fingers_action``, the finger
half of the paper's naive relocation baseline) or, with ``--relative``, from the finger command held at the first
step; on every fifth test object (index 0 mod 5 of the full list, so every trial is seeded as in the full-protocol runs and pairs with them trial by trial), all 25 trials each:

    python docs/runs/relocate_zero/squeeze.py TIGHTEN OUT.json [--disturb] [--relative]

then pairs OUT.json with the zero action and the expert on the same trials
(docs/runs/paper_protocol/relocate_full{,_zero}{,_disturb}.json.gz), through ``fifth.py``.
"""
import argparse
import json
import sys
from functools import partial
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fifth import report, run_fifth  # noqa: E402


def _policy(obs, u, tighten, relative=False):
    """absolute (the naive baseline's fingers): drive the fingers to the grasp pose ``finger_q0`` closed by
    ``tighten``; relative: to the finger command held at the episode's first step closed by ``tighten`` (the zero
    action holds that command, which contact keeps beyond the joints' positions)."""
    from unicross.evaluation import tightened_fingers_action
    if relative and (int(u.elapsed_steps.max()) == 0 or getattr(u, "_squeeze_base", None) is None):
        u._squeeze_base = u.command[:, 6:].clone()
    return tightened_fingers_action(u, tighten, base=u._squeeze_base if relative else None)


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("tighten", type=float)
    p.add_argument("out")
    p.add_argument("--disturb", action="store_true")
    p.add_argument("--relative", action="store_true", help="close from the held command, not from the grasp pose")
    a = p.parse_args()
    trials = run_fifth(partial(_policy, tighten=a.tighten, relative=a.relative), a.disturb)
    json.dump(dict(tighten=a.tighten, relative=a.relative, disturb=a.disturb, objects="test, index 0 mod 5", trials=trials),
              open(a.out, "w"), indent=1, default=float)
    report(trials, f"tighten {a.tighten} rad{' from the held command' if a.relative else ''}", a.disturb)
