"""Translate z-: compositions of one-finger sweeps, each active in a window of control steps or from a state
trigger, scored by the evaluation itself (`unicross.evaluation.run_protocol`: the protocol's environments, trials, stop
and success, as `unicross eval --protocol translate --axis z- --seed 0` runs a policy).

Usage: python docs/runs/translate_zm_reference/finger_sequences.py "SPEC|SPEC|..." OBJECTS LIMIT TRIALS
SPEC: a finger sequence (`unicross.sequences`): '+'-joined terms finger:k:rate:t0:t1 (finger index, middle, ring or
thumb; its k most distal joints; rate rad per control step along the closing direction, negative opens; active for
t0 <= t < t1) or finger:k:rate:@other:theta (active once the command of `other`'s most distal joint has reached
theta rad: a state trigger, which the observation shows, where the time is not).
OBJECTS: an object set (train, test, unseen), LIMIT objects per group, TRIALS per object. The episodes start from the
shipped grasp-state dataset, or from the file UNICROSS_GRASPS names."""
import os
import sys

import torch

import unicross  # noqa: F401  (registers the tasks)
from unicross import evaluation as E
from unicross.objects import get_object_set
from unicross.sequences import make_sequence_policy

torch.set_num_threads(1)


def score_line(spec: str, trials, width: int = 70) -> str:
    """One line per scored motion: successes, drops and successes by shape (also used by ratchet.py, wrist_shake.py)."""
    n, ok = len(trials), sum(t["success"] for t in trials)
    drops = sum(t["dropped"] for t in trials)
    by_shape = {}
    for t in trials:  # object names are CATEGORY-SHAPE-SET-INDEX
        by_shape.setdefault(t["object"].split("-")[1], []).append(t["success"])
    shapes = ", ".join(f"{k} {sum(v)}/{len(v)}" for k, v in sorted(by_shape.items()))
    return f"{spec:{width}s} success {ok}/{n} ({100 * ok / n:.1f}%), drops {drops}; {shapes}"


def main() -> None:
    specs = sys.argv[1].split("|")
    objs = get_object_set(sys.argv[2], limit=int(sys.argv[3]))
    for spec in specs:
        trials = E.run_protocol("translate", make_sequence_policy(spec), objs, trials_per_object=int(sys.argv[4]), seed=0,
                                axes=["z-"], progress=False, grasp_dataset=os.environ.get("UNICROSS_GRASPS"))
        print(score_line(spec, trials), flush=True)


if __name__ == "__main__":
    main()
