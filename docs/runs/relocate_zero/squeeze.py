"""Does a firmer grip beat the zero action on relocation? A diagnosis, not an expert.

The zero action beats the shipped relocate expert on the paper's full test protocol, disturbed and not
(docs/record/full_protocol.md, last section); most of the zero action's failures are drops. This runs the policy
"wrist residual zero, fingers closed by TIGHTEN rad": towards the grasp pose (``tightened_fingers_action``, the finger
half of the paper's naive relocation baseline) or, with ``--relative``, from the finger command held at the first
step; on every fifth test object (index 0 mod 5 of the full list, so every trial is seeded as in the full-protocol runs and pairs with them trial by trial), all 25 trials each:

    python docs/runs/relocate_zero/squeeze.py TIGHTEN OUT.json [--disturb] [--relative]

then pairs OUT.json with the zero action and the expert on the same trials
(docs/runs/paper_protocol/relocate_full{,_zero}{,_disturb}.json.gz).
"""
import argparse
import json
import multiprocessing as mp
import sys
from concurrent.futures import ProcessPoolExecutor
from functools import partial
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "docs/runs/paper_protocol"))
from paired import mcnemar_exact, newcombe_paired  # noqa: E402


def _policy(obs, u, tighten, relative=False):
    """absolute (the naive baseline's fingers): drive the fingers to the grasp pose ``finger_q0`` closed by
    ``tighten``; relative: to the finger command held at the episode's first step closed by ``tighten`` (the zero
    action holds that command, which contact keeps beyond the joints' positions)."""
    from unicross.evaluation import tightened_fingers_action
    if not relative:
        return tightened_fingers_action(u, tighten)
    from unicross.scripted_grasp import closing_direction
    if int(u.elapsed_steps.max()) == 0 or getattr(u, "_squeeze_base", None) is None:
        u._squeeze_base = u.command[:, 6:].clone()
    a = torch.zeros(u.num_envs, u.hand_spec.dof, device=u.device)
    q_des = torch.clamp(u._squeeze_base + closing_direction(u.hand_spec).to(u.device) * tighten,
                        u.q_lower[6:], u.q_upper[6:])
    a[:, 6:] = (q_des - u.command[:, 6:]) / u.action_scale[6:]
    return a.clamp(-1.0, 1.0)


def _shard(tighten, disturb, relative, shard):
    torch.set_num_threads(1)
    from unicross.evaluation import run_protocol
    from unicross.objects import get_object_set
    objects = get_object_set("test")
    return run_protocol("relocate", partial(_policy, tighten=tighten, relative=relative), objects, disturb=disturb, seed=0,
                        trials_per_object=25, shard=shard, progress=False)


def report(trials, tighten, relative, disturb):
    """Prints the run's successes and its paired differences to the zero action and the expert on the same trials."""
    from unicross.evaluation import read_results
    key = lambda t: (t["object"], t["trial"])  # noqa: E731
    mine = {key(t): t for t in trials}
    suffix = "_disturb" if disturb else ""
    print(f"tighten {tighten} rad{' from the held command' if relative else ''}{' --disturb' if disturb else ''}: "
          f"{sum(t['success'] for t in trials)} of {len(trials)} ({sum(t['dropped'] for t in trials)} dropped)")
    for name in (f"relocate_full_zero{suffix}", f"relocate_full{suffix}"):
        full = read_results(ROOT / f"docs/runs/paper_protocol/{name}.json.gz")["trials"]["relocate"]
        other = {key(t): t for t in full if key(t) in mine}
        assert len(other) == len(mine), name
        cells = [0, 0, 0, 0]  # both, only this, only the other, neither
        for k, t in mine.items():
            s, o = t["success"], other[k]["success"]
            cells[0 if s and o else 1 if s else 2 if o else 3] += 1
        lo, hi = newcombe_paired(*cells)
        n = len(mine)
        print(f"  against {name}: {100 * (cells[0] + cells[2]) / n:.1f}% there; this - it "
              f"{100 * (cells[1] - cells[2]) / n:+.1f} points [{100 * lo:+.1f}, {100 * hi:+.1f}], only this {cells[1]}, "
              f"only it {cells[2]}, p = {mcnemar_exact(cells[1], cells[2]):.2g}")


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("tighten", type=float)
    p.add_argument("out")
    p.add_argument("--disturb", action="store_true")
    p.add_argument("--relative", action="store_true", help="close from the held command, not from the grasp pose")
    a = p.parse_args()
    with ProcessPoolExecutor(2, mp_context=mp.get_context("spawn")) as ex:
        parts = list(ex.map(partial(_shard, a.tighten, a.disturb, a.relative), [(0, 10), (5, 10)]))
    trials = [t for part in parts for t in part]
    json.dump(dict(tighten=a.tighten, relative=a.relative, disturb=a.disturb, objects="test, index 0 mod 5", trials=trials),
              open(a.out, "w"), indent=1, default=float)
    report(trials, a.tighten, a.relative, a.disturb)
