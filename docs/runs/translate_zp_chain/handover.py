"""Diagnosis (chooses nothing): the hand-over from relocate to translate z+ in the experts' chain.

Runs the chain grasp,relocate,translate:z+ of ``unicross chain --policy P --objects test --limit 10
--trials-per-object 5 --seed S`` (the same trials) and records, one control step before the hand-over (the state the translate phase
starts from, a step later; the task's velocities restart at 0 with a new phase), the hand's speed (world), the object's speed in the
hand frame, whether the state would pass the chain dataset's settled test
(``settled_in_hand``), and the phase's outcome; prints success by hand-over speed.

    python docs/runs/translate_zp_chain/handover.py [POLICY] [SEED] [OUT.json]    # POLICY default experts:allegro
"""
import json
import sys

import gymnasium as gym

import unicross  # noqa: F401
from unicross.evaluation import resolve_policy
from unicross.objects import get_object_set
from unicross.rl.expert_grasps import settled_in_hand
from unicross.seeding import trial_seed
from unicross.tasks.chain import objects_for_chain, parse_sequence

spec = sys.argv[1] if len(sys.argv) > 1 else "experts:allegro"
seed = int(sys.argv[2]) if len(sys.argv) > 2 else 0
out = sys.argv[3] if len(sys.argv) > 3 else None
modes = parse_sequence("grasp,relocate,translate:z+")
objects = objects_for_chain(get_object_set("test", limit=10), modes)
policy, _ = resolve_policy(spec, "allegro", seed)
rows = []
for oi, obj in enumerate(objects):
    for k in range(5):
        env = gym.make("UniCross-Chain-v1", obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none",
                       hand="allegro", objects=[obj], randomize=False, sequence=modes)
        u = env.unwrapped
        obs, _ = u.reset(seed=trial_seed(seed, oi, k))
        at = last = None
        for t in range(u.phase_ends[-1]):
            if int(u.phase[0]) == 1:  # relocating: the hand-over state if this is its last step
                last = dict(hand_speed=float(u.hand_vel[0].norm()), hand_angspeed=float(u.hand_angvel[0].norm()),
                            obj_speed_h=float(u.obj_vel_h[0].norm()), obj_angspeed_h=float(u.obj_angvel_h[0].norm()),
                            settled=bool(settled_in_hand(u)[0]))
            obs, _, term, _, _ = u.step(policy(obs, u))
            if at is None and int(u.phase[0]) == 2:
                at = last
            if bool(term.all()):
                break
        ps = u.phase_success[0].tolist()
        rows.append(dict(object=obj.name, trial=k, phase_success=ps, reached=bool(ps[0] and ps[1]), **(at or {})))
        env.close()
reached = [r for r in rows if r["reached"] and "hand_speed" in r]
print(f"{spec}, seed {seed}: {len(reached)} chains reached translate z+ after a successful relocation")
for name, sel in (("settled at the hand-over", [r for r in reached if r["settled"]]),
                  ("not settled", [r for r in reached if not r["settled"]])):
    ok = sum(r["phase_success"][2] for r in sel)
    print(f"  {name}: {ok}/{len(sel)}")
qs = sorted(r["hand_speed"] for r in reached)
if qs:
    cut = qs[len(qs) // 2]
    for name, sel in (("hand speed <= median %.3f m/s" % cut, [r for r in reached if r["hand_speed"] <= cut]),
                      ("hand speed > median", [r for r in reached if r["hand_speed"] > cut])):
        ok = sum(r["phase_success"][2] for r in sel)
        print(f"  {name}: {ok}/{len(sel)}")
for r in reached:
    if not r["phase_success"][2]:
        print("  failed:", r["object"], r["trial"], {k: round(v, 3) if isinstance(v, float) else v
                                                    for k, v in r.items() if k not in ("object", "trial")})
if out:
    json.dump(rows, open(out, "w"), indent=1)
