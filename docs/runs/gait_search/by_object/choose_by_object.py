"""A rotate gait chosen by the object (diagnosis, 2026-11-26): the search's selected gaits, each on the
training objects, then on held-out objects each object gets the gait that did best on the training
objects of its group (shape x smallest side below / above 6 cm).

The held-out gaits turn some objects every time and others never (``../orientation/README.md``);
one gait was searched for all objects. This asks whether the gaits the search already kept (its
``--select`` rows, 6 per axis) differ by object enough that choosing among them by group beats the
shipped gait on the same held-out trials (test, first 20 per group, 3 trials, seed 0: the README's).
The choice reads the object's shape and size from the task (privileged, as the gaits' stop is).

    python docs/runs/gait_search/by_object/choose_by_object.py AXIS SEARCH_LOG > AXIS.json
"""
import gzip
import json
import os
import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor

import torch


def group(obj) -> str:
    return f"{obj.shape}-{'small' if min(float(x) for x in obj.dims) < 0.06 else 'large'}"


def run(axis, gait_files, choice, objs, shard):
    """Trials of the rotate protocol on ``objs`` (first 20 per group, 3 trials, seed 0), shard i of 2; the
    gait of each object is ``gait_files[choice[group]]`` (or gait_files[0] without a choice)."""
    torch.set_num_threads(1)
    import unicross  # noqa: F401
    from unicross import evaluation as E
    from unicross.gaits import make_gait_policy
    from unicross.objects import get_object_set
    objects = get_object_set(objs, limit=20)
    by_name = {o.name: o for o in objects}
    gaits = [make_gait_policy(f) for f in gait_files]
    current = {}

    def policy(obs, u):
        if int(u.elapsed_steps[0]) == 0:
            name = u.object_names[int(u.obj_index[0])] if hasattr(u, "object_names") else None
            current["g"] = gaits[choice.get(group(by_name[name]), 0) if choice else 0]
        return current["g"](obs, u)

    out = E.run_protocol("rotate", policy, objects, trials_per_object=3, seed=0, axes=[axis], progress=False,
                         shard=(shard, 2))
    return [dict(t, group=group(by_name[t["object"]])) for t in out]


def both(axis, files, choice, objs):
    with ProcessPoolExecutor(2) as ex:
        parts = list(ex.map(run, [axis] * 2, [files] * 2, [choice] * 2, [objs] * 2, [0, 1]))
    return [t for p in parts for t in p]


if __name__ == "__main__":
    axis, log = sys.argv[1], sys.argv[2]
    rows = [json.loads(line) for line in gzip.open(log, "rt") if line.strip()]
    sel = sorted([r for r in rows if "success" in r], key=lambda r: -r["success"])
    tmp = tempfile.mkdtemp()
    files = []
    for k, r in enumerate(sel):
        f = os.path.join(tmp, f"gait{k}.json")
        with open(f, "w") as fh:
            json.dump(dict(mode=f"rotate_{axis}", p=r["p"], meta=r["meta"], success=r["success"]), fh)
        files.append(f)
    train = {}
    for k, f in enumerate(files):
        trials = both(axis, [f], None, "train")
        for t in trials:
            train.setdefault(t["group"], [[0, 0] for _ in files])[k][0] += t["success"]
            train[t["group"]][k][1] += 1
        print(f"gait {k} (selection {sel[k]['success']:.3f}): train {sum(t['success'] for t in trials)} / "
              f"{len(trials)}", file=sys.stderr, flush=True)
    choice = {g: max(range(len(files)), key=lambda k: (v[k][0], -k)) for g, v in train.items()}
    test_sel = both(axis, files, choice, "test")
    test_one = both(axis, files, None, "test")  # the search's best gait alone (the shipped one)
    res = dict(axis=axis, log=log, selection_success=[r["success"] for r in sel], train_by_group=train,
               choice=choice, test_selected=sum(t["success"] for t in test_sel),
               test_best_gait=sum(t["success"] for t in test_one), n=len(test_sel),
               test_by_group={g: [sum(t["success"] for t in tr if t["group"] == g) for tr in (test_sel, test_one)]
                              + [sum(t["group"] == g for t in test_sel)] for g in train},
               trials_selected=test_sel, trials_best_gait=test_one)
    json.dump(res, sys.stdout, indent=1)
