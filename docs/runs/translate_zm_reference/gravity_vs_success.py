"""Does the translate z- expert's success depend on how the hand is oriented? (diagnosis, 2026-12-03)

The translate protocol starts every trial in a random wrist orientation, and a stick pulled toward the wrist (z-)
has gravity with it when the fingertips point up and against it when they point down. For each trial this records
gravity's direction in the hand's start frame (x_h: palm normal, z_h: towards the fingertips) and the outcome, on
the trials of ``unicross eval --policy P --protocol translate --axis z- --objects OBJS --limit L
--trials-per-object 3 --seed 0`` (two processes), as ``docs/runs/gait_search/orientation/gravity_vs_success.py``
does for the rotate gaits:

    python docs/runs/translate_zm_reference/gravity_vs_success.py allegro/translate_z- test 20 OUT.json
"""
import json, sys
import torch
def shard_trials(spec, objs, limit, shard):
    torch.set_num_threads(1)
    import unicross  # noqa
    from unicross import evaluation as E
    from unicross.geometry import quat_apply, quat_inv
    from unicross.objects import get_object_set
    pol, _ = E.resolve_policy(spec, "allegro", seed=0)
    grav = []
    def policy(obs, u):
        if int(u.elapsed_steps[0]) == 0:
            g = torch.tensor([[0.0, 0.0, -1.0]]).expand(u.num_envs, 3)
            grav.append(quat_apply(quat_inv(u.root_q), g)[0].tolist())
        return pol(obs, u)
    out = E.run_protocol("translate", policy, get_object_set(objs, limit=limit), trials_per_object=3, seed=0,
                         axes=["z-"], progress=False, shard=shard)
    return [dict(t, gravity_h=g) for t, g in zip(out, grav)]
if __name__ == "__main__":
    from concurrent.futures import ProcessPoolExecutor
    import multiprocessing as mp
    spec, objs, limit = sys.argv[1], sys.argv[2], int(sys.argv[3])
    with ProcessPoolExecutor(2, mp_context=mp.get_context("spawn")) as ex:
        parts = list(ex.map(shard_trials, [spec]*2, [objs]*2, [limit]*2, [(0,2),(1,2)]))
    trials = [t for p in parts for t in p]
    json.dump(trials, open(sys.argv[4], "w"))
    for comp, name in ((2, "z_h (+1: fingertips down)"), (0, "x_h (+1: palm down)")):
        bins = {"< -0.5": [], "-0.5..0.5": [], "> 0.5": []}
        for t in trials:
            v = t["gravity_h"][comp]
            bins["< -0.5" if v < -0.5 else "> 0.5" if v > 0.5 else "-0.5..0.5"].append(t)
        print(name, {k: f"{sum(t['success'] for t in b)}/{len(b)} ({sum(t['dropped'] for t in b)} dropped)" for k, b in bins.items()})
