"""Does the physics setting, not the policy, limit in-hand rotation? A probe, not a protocol.

Runs a policy (anything ``unicross eval --policy`` takes) on one in-hand protocol with the task's
``sim`` section overridden (``KEY=VALUE`` pairs, e.g. ``solver_position_iterations=20``; ``disturb`` adds the evaluation's
``--disturb`` force), on the
first LIMIT objects per group x TRIALS starts (the evaluation's trials and seeds), and prints
successes, drops and the mean turn, shift or pose error of the trials kept (AXIS ``-`` for
protocols without axes):

    python docs/runs/physics_settings/probe.py POLICY PROTOCOL AXIS OBJECTS LIMIT TRIALS OUT.json [KEY=VALUE ...] [disturb]

Every override applies to the scene the evaluation builds (``unicross.tasks.base`` reads ``configs/task.yaml``
through ``load_config``, patched here); the grasp states are the shipped dataset's, made under the
default settings.
"""
import json
import sys
import time

import torch


def main():
    policy_spec, protocol, axis, objects, limit, trials, out = sys.argv[1:8]
    sim, disturb = {}, "disturb" in sys.argv[8:]
    for kv in sys.argv[8:]:
        if kv == "disturb":
            continue
        k, v = kv.split("=")
        sim[k] = type(eval(v))(eval(v))
    torch.set_num_threads(1)
    import unicross.tasks.base as base
    from unicross.config import load_config as _load

    def load_config(name, overrides=None):
        cfg = _load(name, overrides)
        if name == "task":
            cfg["sim"].update(sim)
        return cfg
    base.load_config = load_config
    from unicross.evaluation import resolve_policy, run_protocol
    from unicross.objects import get_object_set
    policy, _ = resolve_policy(policy_spec, "allegro")
    t0 = time.time()
    rows = run_protocol(protocol, policy, get_object_set(objects, limit=int(limit)), axes=None if axis == "-" else [axis],
                        trials_per_object=int(trials), seed=0, disturb=disturb, progress=False)
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
