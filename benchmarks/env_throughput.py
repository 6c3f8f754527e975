"""Control steps/s of every UniCross task id on the CPU, and the ratio to bare physics.

For each id the env steps with small random wrist actions and still fingers from a reset
(relocate/rotate/translate start from a grasp, so the hand holds the object; grasp runs the
scripted grasp first so the hand holds it too)
and we time (a) ``env.step`` with the step math eager (``UNICROSS_COMPILE=0``), compiled
(``UNICROSS_COMPILE=1``: ``GraphMethod``, after its graph is compiled or loaded from the cache) and
through ``torch.compile`` (``UNICROSS_COMPILE=torch``: Dynamo, the compiled path before
``GraphMethod``) and (b) bare physics
of the same scene: the same number of PhysX substeps per control step with no task code. All are
measured in this one run, interleaved, and reported as steps/s and as ratios to bare physics.

A second table compares the physics settings that decide speed (hand self-collision, contact
offset, solver position iterations) on a holding scene: bare physics control steps/s for each combination.

    python benchmarks/env_throughput.py [--hand allegro] [--steps 300] [--reps 5] [--breakdown] [--json out.json] [--no-settings]
        [--modes eager torch.compile compiled] [--tasks UniCross-Rotate-v1 ...]

``--modes`` / ``--tasks`` time a subset (e.g. ``--modes compiled`` on a fresh machine, where every
compiled mode first compiles each task's graph: ~1 min each); a mode left out reports null. Each
task's row is printed as JSON as soon as it is measured.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time

import torch

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import gymnasium as gym  # noqa: E402

import unicross  # noqa: E402,F401
from unicross.config import load_config  # noqa: E402
from unicross.scripted_grasp import ScriptedGrasp, synthesize  # noqa: E402
from unicross.objects import get_object_set  # noqa: E402

TASKS = [("UniCross-Grasp-v1", {}), ("UniCross-Relocate-v1", {}), ("UniCross-Rotate-v1", {"axis": "z+"}),
         ("UniCross-Translate-v1", {"direction": "z+"}), ("UniCross-MultiSkill-v1", {})]


def held_objects(hand: str = "allegro"):
    """(scripted grasps, objects): one training object per group and a scripted grasp of each, keeping the
    objects that have one (in-hand tasks start from a grasp of each object)."""
    objects = get_object_set("train", limit=1)
    gs, _ = synthesize(hand, objects, per_object=1, seed=0, progress=False)
    have = {n for n, c in gs.counts().items() if c}
    return gs, [o for o in objects if o.name in have]


def _holding_env(task, kw, grasps, objects, hand="allegro", **extra):
    env = gym.make(task, obs_mode="state", sim_backend="physx_cpu", render_backend="none", objects=objects, hand=hand,
                   grasp_dataset=grasps, randomize=False, config=dict(grasp=dict(lift_after=None)), **kw, **extra)
    u = env.unwrapped
    u.reset(seed=0)
    if task == "UniCross-Grasp-v1":
        policy = ScriptedGrasp(u)
        for _ in range(policy.t_lift + 5):
            u.step(policy())
    return env, u


def _time_env(u, steps, seed=0):
    """env.step with small random wrist actions and fingers holding their grip (the hand keeps the
    object and every body stays awake); returns (steps/s, joint commands, joints, mean links in contact)."""
    g = torch.Generator().manual_seed(seed)
    actions = torch.zeros(steps, 1, u.hand_spec.dof)
    actions[..., :6] = (torch.rand(steps, 1, 6, generator=g) * 2 - 1) * 0.3
    actions = list(actions.unbind(0))  # the per-step views made before the clock starts
    commands, contacts = [], []
    t = time.perf_counter()
    for a in actions:  # only references are kept inside the loop: no tensor op of the benchmark's own
        *_, info = u.step(a)
        commands.append(u.command)
        contacts.append(info["num_contacts"])
    rate = steps / (time.perf_counter() - t)
    contacts = torch.stack(contacts).sum()
    art = u.agent.robot._objs[0]
    joints = [art.active_joints[i] for i in u._drive_idx.tolist()]  # actuated joints, then mimic followers
    targets = [torch.cat([c, u._follow(c)], dim=-1)[0].tolist() for c in commands]
    return rate, targets, joints, float(contacts.item()) / steps


# (mode, UNICROSS_COMPILE value)
MODES = (("eager", "0"), ("torch.compile", "torch"), ("compiled", "1"))

TIMED = ("_command_math", "_apply_command", "_step_action", "_read", "_step_math", "get_info")


def _breakdown(u, steps):
    """Per-step microseconds of the parts of ``env.step`` (``TIMED``; ``_step_action`` holds the
    PhysX substeps, ``get_info`` the reads and the step math), timed inside the step loop."""
    spent = dict.fromkeys(TIMED, 0.0)
    own = {name: u.__dict__[name] for name in TIMED if name in u.__dict__}  # the task's compiled methods
    for name in TIMED:
        fn = getattr(u, name)

        def timed(*a, _fn=fn, _name=name, **k):
            t = time.perf_counter()
            out = _fn(*a, **k)
            spent[_name] += time.perf_counter() - t
            return out
        setattr(u, name, timed)
    try:
        rate, *_ = _time_env(u, steps)
    finally:
        for name in TIMED:
            if name in own:
                setattr(u, name, own[name])
            else:
                delattr(u, name)  # the class's method again
    return dict(step=round(1e6 / rate, 1), **{k: round(v / steps * 1e6, 1) for k, v in spent.items()})


def _time_physics(u, commands, joints):
    """Bare physics of the same scene: the same drive targets, PhysX substeps, no task code."""
    k = u._sim_steps_per_control
    t = time.perf_counter()
    for cmd in commands:
        for j, target in zip(joints, cmd):
            j.set_drive_target(target)
        for _ in range(k):
            u.scene.step()
    return len(commands) / (time.perf_counter() - t)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--steps", type=int, default=300)
    p.add_argument("--reps", type=int, default=5, help="interleaved repetitions; rates are their medians")
    p.add_argument("--json", default=None)
    p.add_argument("--hand", default="allegro")
    p.add_argument("--breakdown", action="store_true",
                   help="also time the parts of a compiled step inside the loop (us per step)")
    p.add_argument("--no-settings", dest="settings", action="store_false", help="skip the physics-settings table")
    p.add_argument("--modes", nargs="+", choices=[m for m, _ in MODES], default=[m for m, _ in MODES],
                   help="step-math modes to time (bare physics is always timed)")
    p.add_argument("--tasks", nargs="+", choices=[t for t, _ in TASKS], default=[t for t, _ in TASKS])
    args = p.parse_args()
    torch.set_num_threads(1)
    gs, objects = held_objects(args.hand)
    print(f"hand {args.hand}: {len(objects)} objects with a scripted grasp")
    rows = []
    for task, kw in TASKS:
        if task not in args.tasks:
            continue
        built = {}
        try:
            for mode, flag in MODES:
                if mode not in args.modes:
                    continue
                os.environ["UNICROSS_COMPILE"] = flag  # read when an env is made
                env, u = _holding_env(task, kw, gs, objects, hand=args.hand)
                _time_env(u, 5)  # the compiled env compiles (or loads its graph) here
                built[mode] = (env, u, u.get_state_dict())
        except ValueError as e:  # e.g. no elongated grasp for translate
            print(f"{task}: skipped ({e})")
            continue
        rates = {m: [] for m in built}
        phys_rates = []
        for _ in range(args.reps):  # interleave to share machine noise
            for mode, (env, u, state) in built.items():
                u.set_state_dict(state)
                rate, commands, joints, contacts = _time_env(u, args.steps)
                rates[mode].append(rate)
                u.set_state_dict(state)
                phys_rates.append(_time_physics(u, commands, joints))
        # medians of the interleaved repetitions (a shared VM's noise: single runs differ by up to ~30%)
        b = statistics.median(phys_rates)
        med = {m: statistics.median(rates[m]) if m in rates else None for m, _ in MODES}
        row = dict(task=task)
        for m, _ in MODES:
            row[f"{m.replace('.', '_')}_steps_per_s"] = None if med[m] is None else round(med[m], 1)
        row["bare_physics_steps_per_s"] = round(b, 1)
        for m, _ in MODES:
            row[f"{m.replace('.', '_')}_ratio"] = None if med[m] is None else round(med[m] / b, 3)
        row.update(contacts=round(contacts, 1), repetitions=args.reps,
                   runs={**{m: [round(r, 1) for r in v] for m, v in rates.items()},
                         "physics": [round(r, 1) for r in phys_rates]})
        rows.append(row)
        print(json.dumps({k: v for k, v in row.items() if k != "runs"}), flush=True)
        if args.breakdown and "compiled" in built:
            u, state = built["compiled"][1:]
            u.set_state_dict(state)
            rows[-1]["compiled_breakdown_us"] = _breakdown(u, args.steps)
            print(f"{task}: compiled step, us per step: {rows[-1]['compiled_breakdown_us']}")
        for env, *_ in built.values():
            env.close()
    print(f"{'task':28s} {'eager/s':>8s} {'torch.compile/s':>16s} {'compiled/s':>11s} {'physics/s':>10s} "
          f"{'eager ratio':>12s} {'torch.compile ratio':>20s} {'compiled ratio':>15s} {'links in contact':>17s}")
    def f(v, width, digits):
        return f"{'--':>{width}s}" if v is None else f"{v:{width}.{digits}f}"
    for r in rows:
        print(f"{r['task']:28s} {f(r['eager_steps_per_s'], 8, 0)} {f(r['torch_compile_steps_per_s'], 16, 0)} "
              f"{f(r['compiled_steps_per_s'], 11, 0)} {r['bare_physics_steps_per_s']:10.0f} {f(r['eager_ratio'], 12, 2)} "
              f"{f(r['torch_compile_ratio'], 20, 2)} {f(r['compiled_ratio'], 15, 2)} {r['contacts']:17.1f}")
    settings = []
    ours = load_config("task")["sim"]["solver_position_iterations"]
    combos = [(True, 0.02, ours), (True, 0.002, ours), (False, 0.02, ours), (False, 0.002, ours)] \
        + [(False, 0.002, n) for n in (8, 12, 16, 20) if n != ours]
    for self_collision, offset, iterations in (combos if args.settings else []):
        env, u = _holding_env("UniCross-Relocate-v1", {}, gs, objects, hand=args.hand,
                              hand_overrides=dict(self_collision=self_collision),
                              sim_config=dict(scene_config=dict(contact_offset=offset,
                                                                solver_position_iterations=iterations)))
        state = u.get_state_dict()
        _, commands, joints, _ = _time_env(u, args.steps)
        rates = []
        for _ in range(2):
            u.set_state_dict(state)
            rates.append(_time_physics(u, commands, joints))
        settings.append(dict(self_collision=self_collision, contact_offset=offset, solver_position_iterations=iterations,
                             bare_physics_steps_per_s=round(max(rates), 1)))
        env.close()
    if settings:
        print("\nphysics settings (relocate scene, hand holding the object), bare physics control steps/s:")
        base = settings[0]["bare_physics_steps_per_s"]
    for s in settings:
        print(f"  self_collision={str(s['self_collision']):5s} contact_offset={s['contact_offset']:<6} "
              f"solver_position_iterations={s['solver_position_iterations']:<3d}"
              f"{s['bare_physics_steps_per_s']:8.0f}  ({s['bare_physics_steps_per_s'] / base:.2f}x the first row)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(dict(tasks=rows, physics_settings=settings), f, indent=1)


if __name__ == "__main__":
    main()
