"""Translate z-: scripted finger behaviours on training elongated objects, eval-like conditions (50 steps).

Usage: python docs/runs/translate_zm_reference/scripted_pulls.py "SPEC|SPEC|..." LIMIT SEEDS
SPEC: close=RATE (rad/step along the closing direction); fingers=0123 (index, middle, ring, thumb);
joints=23 (joint positions within each finger); stop=M (hold once the object has moved M); cycle=UP:DOWN
(close UP steps, reopen DOWN steps); wz=A or wz=rampA:B (wrist residual along the hand z).

All behaviours of an object run in one env one after another, and PhysX state carries across resets,
so a behaviour's numbers depend on the ones before it; finger_sequences.py scores behaviours as the
evaluation does (a fresh env each) and is the one to compare with `unicross eval`."""
import sys, torch, gymnasium as gym
sys.path.insert(0, ".")
import unicross  # noqa
from unicross.objects import get_object_set
from unicross.rl.ppo import env_kwargs_for
from unicross.config import load_config
from unicross.audit import finger_sweep_action
from unicross.seeding import trial_seed
torch.set_num_threads(1)
cfg = load_config("ppo", None)
kw = env_kwargs_for("translate", "z-", "allegro", cfg["env"]); kw.pop("object_limit", None); kw.pop("reconfiguration_freq", None)
kw["randomize"] = False
STEPS = 50
def beh(spec, u):
    parts = dict(p.split("=") for p in spec.split(";"))
    close = float(parts.get("close", 0)); wz = parts.get("wz", "0"); t0 = int(parts.get("t0", 0))
    base = finger_sweep_action(u.hand_spec, close)[None] if close else torch.zeros(1, u.hand_spec.dof)
    if "fingers" in parts:
        keep = torch.zeros(u.hand_spec.dof, dtype=torch.bool); keep[:6] = True
        for f in parts["fingers"]:
            keep[6 + 4 * int(f): 10 + 4 * int(f)] = True
        if "joints" in parts:  # joint positions within each finger to keep
            jm = torch.zeros(u.hand_spec.dof, dtype=torch.bool); jm[:6] = True
            for f in range(4):
                for j in parts["joints"]:
                    jm[6 + 4 * f + int(j)] = True
            keep &= jm
        base = base * keep
    stop = float(parts.get("stop", 9))
    state = dict(done=False)
    def act(t):
        if u.trans_acc[0] > stop:
            state["done"] = True
        if state["done"]:
            return torch.zeros_like(base)
        a = base.clone() if t >= t0 else torch.zeros_like(base)
        if "cycle" in parts:
            up, down = (int(x) for x in parts["cycle"].split(":"))
            if t % (up + down) >= up:
                a = -a * up / down
        if wz.startswith("ramp"):
            lo, hi = map(float, wz[4:].split(":"))
            a[0, 2] = lo + (hi - lo) * min(t / (STEPS - 1), 1.0)
        else:
            a[0, 2] = float(wz)
        return a
    return act
specs = sys.argv[1].split("|")
objs = get_object_set("train-elongated", limit=int(sys.argv[2]))
seeds = int(sys.argv[3])
tot = {s: [0, 0.0] for s in specs}
for oi, obj in enumerate(objs):
    env = gym.make("UniCross-Translate-v1", obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none", num_envs=1, **{**kw, "objects": [obj]})
    u = env.unwrapped
    for k in range(seeds):
        row = []
        for s in specs:
            u.reset(seed=trial_seed(0, oi, k))
            act = beh(s, u); best = 0.0; dropped = False
            for t in range(STEPS):
                _, r, term, trunc, info = u.step(act(t))
                best = max(best, float(info["translation"][0]) if "translation" in info else 0.0)
                dropped = dropped or bool(info["drop"][0])
            ok = best > 0.05 and not dropped
            tot[s][0] += ok; tot[s][1] += best
            row.append(f"{100*best:5.1f}{'S' if ok else ('d' if dropped else '-')}")
        print(f"{obj.name[-14:]:14s} s{k} " + " ".join(row), flush=True)
    env.close()
n = len(objs) * seeds
for s in specs: print(f"{s:40s} success {tot[s][0]}/{n}, mean best {100*tot[s][1]/n:.1f} cm")
