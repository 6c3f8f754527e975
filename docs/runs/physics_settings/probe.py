"""Does the physics setting, not the policy, limit in-hand rotation? A probe, not a protocol.

Runs a policy (anything ``unicross eval --policy`` takes) on one in-hand protocol with the task's
``sim`` section overridden (``KEY=VALUE`` pairs, e.g. ``solver_position_iterations=20``; ``disturb`` adds the evaluation's
``--disturb`` force), on the
first LIMIT objects per group x TRIALS starts (the evaluation's trials and seeds), and prints
successes, drops and the mean turn, shift or pose error of the trials kept (AXIS ``-`` for
protocols without axes):

    python docs/runs/physics_settings/probe.py POLICY PROTOCOL AXIS OBJECTS LIMIT TRIALS OUT.json [KEY=VALUE ...] [disturb]

Every override applies to every env the evaluation builds (``run_protocol(sim=...)``, as ``unicross eval --sim``;
the first runs of 2026-12-04 patched the task's ``load_config`` to the same effect); the grasp states are the
shipped dataset's, made under the default settings.
"""
import json
import sys
import time

import torch


def main():
    policy_spec, protocol, axis, objects, limit, trials, out = sys.argv[1:8]
    from unicross.config import parse_sim_overrides
    disturb = "disturb" in sys.argv[8:]
    sim = parse_sim_overrides([kv for kv in sys.argv[8:] if kv != "disturb"])
    torch.set_num_threads(1)
    from unicross.evaluation import resolve_policy, run_protocol
    from unicross.objects import get_object_set
    policy, _ = resolve_policy(policy_spec, "allegro")
    t0 = time.time()
    rows = run_protocol(protocol, policy, get_object_set(objects, limit=int(limit)), axes=None if axis == "-" else [axis],
                        trials_per_object=int(trials), seed=0, disturb=disturb, progress=False,
                        sim=sim or None)
    metric = dict(rotate="rotation_rad", translate="translation_cm", relocate="pe_cm").get(protocol)
    kept = [r[metric] for r in rows if not r["dropped"] and metric]
    res = dict(policy=policy_spec, protocol=protocol, axis=axis, objects=objects, limit=int(limit), sim=sim, disturb=disturb,
               n=len(rows), success=sum(r["success"] for r in rows), dropped=sum(r["dropped"] for r in rows),
               mean_kept=sum(kept) / max(len(kept), 1), wall_s=time.time() - t0, trials=rows)
    with open(out, "w") as f:
        json.dump(res, f)
    print(f"{policy_spec} {protocol} {axis} {objects} sim={sim}{' disturb' if disturb else ''}: {res['success']}/{res['n']} success, "
          f"{res['dropped']} dropped, mean kept {res['mean_kept']:.2f}, {res['wall_s']:.0f} s", flush=True)


if __name__ == "__main__":
    main()
