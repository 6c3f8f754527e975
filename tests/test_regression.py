"""Regression pin: a small evaluation of the shipped grasp expert and of scripted/zero baselines
must give the trials recorded in ``tests/data/regression_pin.json`` (same seeds, same objects).

Refactors of the tasks, the formulation or the evaluation must keep these trials: successes, drops
and step counts exactly, the continuous metrics to a small tolerance (the physics and the step math
are deterministic on one machine; the tolerance only absorbs float differences between CPUs). A
deliberate behaviour change regenerates the pin, and says why in its commit:

    UNICROSS_COMPILE=0 python tests/test_regression.py --write
"""
import json
import math
import os
import sys

import pytest

PIN = os.path.join(os.path.dirname(__file__), "data", "regression_pin.json")
# (protocol, policy): the shipped grasp expert, the scripted relocation baseline, the zero action
CASES = [("grasp", "allegro/grasp"), ("relocate", "scripted-relocate"), ("translate", "zero")]
EXACT = ("object", "axis", "trial", "seed", "steps", "dropped", "success")
TOLERANCE = {"pe_cm": 0.2, "ae_rad": 0.01, "lift_cm": 0.2, "rotation_rad": 0.01, "translation_cm": 0.2}


def _evaluate():
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    objects = get_object_set("test", limit=1)  # the first test object of each (category, shape) group
    out = {}
    for protocol, spec in CASES:
        policy, _ = E.resolve_policy(spec, "allegro")
        out[f"{protocol}:{spec}"] = E.run_protocol(protocol, policy, objects, trials_per_object=1, seed=11,
                                                   progress=False)
    return out


def _close(key, a, b):
    if a is None or b is None or isinstance(a, bool) or not isinstance(a, float):
        return a == b
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return abs(a - b) <= TOLERANCE.get(key, 1e-3 * max(1.0, abs(b)))


# Trials whose outcome may flip between CPUs: a trial on the edge of a drop can end either way after the
# float differences of another CPU have grown over 70 steps (2026-11-28: the grasp expert on
# wrappable-box-test-100 dropped it at step 71 on the VM that wrote the pin and held it on another,
# every other trial equal). One such trial is tolerated; a change of behaviour moves more.
FLIPS_ALLOWED = 1


def test_pinned_evaluation_is_unchanged():
    if not os.path.exists(PIN):
        pytest.fail(f"{PIN} is missing; write it with: python tests/test_regression.py --write")
    pinned = json.load(open(PIN))
    now = _evaluate()
    assert sorted(now) == sorted(pinned)
    flipped = []
    for case, trials in pinned.items():
        assert len(now[case]) == len(trials), case
        for got, want in zip(now[case], trials):
            assert all(got.get(k) == want.get(k) for k in ("object", "axis", "trial", "seed")), (case, want)
            if any(got.get(k) != want.get(k) for k in EXACT):
                flipped.append((case, want["object"], {k: (got.get(k), want.get(k)) for k in EXACT
                                                       if got.get(k) != want.get(k)}))
                continue
            for k, v in want.items():
                assert _close(k, got.get(k), v), (case, want["object"], k, got.get(k), v)
    assert len(flipped) <= FLIPS_ALLOWED, flipped


if __name__ == "__main__":
    if "--write" not in sys.argv:
        sys.exit("usage: UNICROSS_COMPILE=0 python tests/test_regression.py --write")
    os.makedirs(os.path.dirname(PIN), exist_ok=True)
    with open(PIN, "w") as f:
        json.dump(_evaluate(), f, indent=1)
    print(f"wrote {PIN}")
