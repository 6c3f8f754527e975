"""Relocation drops in the chain (`python docs/runs/experts_chain/relocation_probe.py zero|expert`): the
chain_test.json trials whose relocation failed (and 14 successful stick trials) re-run as grasp,relocate with the relocate phase acted on by
the relocate expert or the zero action; records the object's speed in the hand at the switch (the
grasp-state dataset keeps grasps with < 0.05 m/s and < 0.5 rad/s); prints each trial and writes
relocation_probe_<which>.json here."""
import json, sys, torch, gymnasium as gym
import unicross  # noqa
from unicross import evaluation as E
from unicross.objects import get_object_set
d = json.load(open("docs/runs/experts_chain/chain_test.json"))
objs = {o.name: o for o in get_object_set("test", limit=10)}
grasp, _ = E.resolve_policy("allegro/grasp", "allegro")
reloc, _ = E.resolve_policy("allegro/relocate", "allegro")
which = sys.argv[1]
rows = []
cases = [t for t in d["trials"] if t["phase_success"][0]]
fails = [t for t in cases if not t["phase_success"][1]]
oks = [t for t in cases if t["phase_success"][1] and t["object"].startswith("elongated-cylinder")][:14]
for tag, group in (("fail", fails), ("ok", oks)):
    for t in group:
        env = gym.make("UniCross-Chain-v1", obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none",
                       hand="allegro", objects=[objs[t["object"]]], randomize=False, sequence=t["sequence"][:2])
        u = env.unwrapped
        obs, _ = u.reset(seed=t["seed"])
        drop = None
        for s in range(u.phase_ends[-1]):
            if int(u.phase[0]) == 0:
                a = grasp(obs, u)
            else:
                a = reloc(obs, u) if which == "expert" else torch.zeros_like(a)
            obs, _, term, trunc, info = u.step(a)
            if s + 1 == u.phase_ends[0] - 1:  # the grasp phase's last state before the switch re-bases the task state
                pos, quat = u.sensor.poses()
                # the grasp-state dataset keeps a grasp only if the object is settled in the hand (expert_grasps)
                at_switch = dict(obj_z=float(pos[0, -1, 2]), hand_z=float(pos[0, 0, 2]),
                                 obj_speed_hand=float(u.obj_vel_h.norm(dim=-1)[0]),
                                 obj_angspeed_hand=float(u.obj_angvel_h.norm(dim=-1)[0]))
            if bool(term.all()):
                drop = s
                break
        rows.append(dict(tag=tag, object=t["object"], seed=t["seed"], reloc_ok=bool(u.phase_success[0, 1]), drop=drop, **at_switch))
        env.close()
        print(rows[-1], flush=True)
json.dump(rows, open(f"docs/runs/experts_chain/relocation_probe_{which}.json", "w"), indent=0)
for tag in ("fail", "ok"):
    r = [x for x in rows if x["tag"] == tag]
    print(which, tag, sum(x["reloc_ok"] for x in r), "/", len(r))
