"""How often a grasp policy's grasp is settled at the end of the grasp protocol (the moment a chain
switches to relocation). ``python docs/runs/grasp_settle/probe.py POLICY OUT.json [--objects test]
[--limit 10] [--trials 3]``: the report's grasp cell (first ``limit`` objects of each group, ``trials``
per object, the evaluation's trial seeds), deterministic actions; per trial: success (lifted, never
dropped) and the object's speed in the hand frame at the last step; "settled" is the grasp-state
dataset's test (< 0.05 m/s and < 0.5 rad/s, ``unicross/rl/expert_grasps.py``)."""
import argparse, json, time
import gymnasium as gym
import unicross  # noqa: F401
from unicross import evaluation as E
from unicross.objects import get_object_set
from unicross.rl.expert_grasps import settled_in_hand
from unicross.seeding import trial_seed

p = argparse.ArgumentParser()
p.add_argument("policy"); p.add_argument("out")
p.add_argument("--objects", default="test"); p.add_argument("--limit", type=int, default=10)
p.add_argument("--trials", type=int, default=3)
a = p.parse_args()
policy, _ = E.resolve_policy(a.policy, "allegro")
rows, t0 = [], time.time()
for oi, obj in enumerate(get_object_set(a.objects, limit=a.limit)):
    env = gym.make("UniCross-Grasp-v1", obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none",
                   hand="allegro", objects=[obj], randomize=False)
    u = env.unwrapped
    for t in range(a.trials):
        obs, _ = u.reset(seed=trial_seed(0, oi, t))
        for _ in range(int(u.episode_length[0])):
            obs, _, term, _, info = u.step(policy(obs, u))
            if bool(term.all()):
                break
        v, w = float(u.obj_vel_h.norm(dim=-1)[0]), float(u.obj_angvel_h.norm(dim=-1)[0])
        ok = bool(info["success"][0]) and not bool(info["ever_dropped"][0])
        rows.append(dict(object=obj.name, trial=t, success=ok, speed=v, angspeed=w, settled=ok and bool(settled_in_hand(u)[0])))
    env.close()
groups = {}
for r in rows:
    g = r["object"].rsplit("-", 2)[0]
    groups.setdefault(g, []).append(r)
summary = {g: dict(n=len(rs), success=sum(r["success"] for r in rs), settled=sum(r["settled"] for r in rs))
           for g, rs in [("all", rows)] + sorted(groups.items())}
json.dump(dict(policy=a.policy, objects=a.objects, limit=a.limit, trials=a.trials, summary=summary, trials_rows=rows,
               wall_s=round(time.time() - t0, 1)), open(a.out, "w"), indent=1)
for g, s in summary.items():
    print(f"{g:24s} n={s['n']:3d} success={s['success']:3d} settled={s['settled']:3d}")
