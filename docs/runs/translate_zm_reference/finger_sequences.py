"""Translate z-: compositions of one-finger sweeps, each active in a window of control steps, scored by
the evaluation itself (`unicross.evaluation.run_protocol`: the protocol's environments, trials, stop
and success, as `unicross eval --protocol translate --axis z- --seed 0` runs a policy).

Usage: python docs/runs/translate_zm_reference/finger_sequences.py "SPEC|SPEC|..." OBJECTS LIMIT TRIALS
SPEC: '+'-joined terms finger:k:rate:t0:t1 (finger index, middle, ring or thumb; its k most distal joints;
rate rad per control step along the closing direction, negative opens; active for t0 <= t < t1).
OBJECTS: an object set (train, test, unseen), LIMIT objects per group, TRIALS per object."""
import sys

import torch

import unicross  # noqa: F401  (registers the tasks)
from unicross import evaluation as E
from unicross.audit import finger_sweep_action
from unicross.objects import get_object_set

torch.set_num_threads(1)


def behaviour(spec: str):
    """A policy (obs, env) -> action [n, dof] that sums the spec's sweeps active at the env's step."""
    cache = {}

    def policy(obs, u) -> torch.Tensor:
        if "terms" not in cache:
            cache["terms"] = []
            for term in spec.split("+"):
                finger, k, rate, t0, t1 = term.split(":")
                sweep = finger_sweep_action(u.hand_spec, float(rate), (finger, int(k))).to(u.device)
                cache["terms"].append((sweep, int(t0), int(t1)))
        t = u.elapsed_steps.to(u.device)[:, None]  # [n, 1]: the control step about to be taken
        a = torch.zeros(u.num_envs, u.hand_spec.dof, device=u.device)
        for sweep, t0, t1 in cache["terms"]:
            a = a + sweep * ((t >= t0) & (t < t1))
        return a.clamp(-1.0, 1.0)
    return policy


def main() -> None:
    specs = sys.argv[1].split("|")
    objs = get_object_set(sys.argv[2], limit=int(sys.argv[3]))
    for spec in specs:
        trials = E.run_protocol("translate", behaviour(spec), objs, trials_per_object=int(sys.argv[4]), seed=0,
                                axes=["z-"], progress=False)
        n, ok = len(trials), sum(t["success"] for t in trials)
        drops = sum(t["dropped"] for t in trials)
        print(f"{spec:70s} success {ok}/{n} ({100 * ok / n:.1f}%), drops {drops}", flush=True)


if __name__ == "__main__":
    main()
