"""``unicross`` command line.

    unicross info                         task ids, observation/action sizes, the target table
    unicross hands                        registered hands and their DoF
    unicross grasps --objects SET ...     synthesise a grasp-state dataset (scripted) and hold-test it
    unicross rollout --task ID ...        run random or zero actions and print per-term rewards
    unicross export RUN --out FILE.pt     ship a run's policy (weights + normaliser) with a JSON sidecar
    unicross audit --skill SKILL          reward audit: returns of reference behaviours as PPO sees them
    unicross train --skill SKILL ...      train one expert with PPO (resumable)
    unicross distill --experts DIR ...    DAgger distillation of the ten experts into one student
    unicross chain --policy P --sequence grasp,relocate,rotate:x+   one continuous long-horizon episode
    unicross eval --policy P ...          the paper's evaluation protocols -> JSON + table
    unicross report FILES...              assemble eval results into the paper's tables
    unicross report --paper               evaluate the shipped checkpoints -> docs/results.md (paper layout)
    unicross render TRAJ --out V.mp4      draw a trajectory file (no GPU needed)

Bad input (unknown skill/axis/hand/object set, missing files) fails before any simulation.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path


def _cmd_info(args) -> int:
    import unicross
    from unicross import formulation as F
    from unicross.robots.hand import available_hands, load_hand
    spec = load_hand(args.hand)
    L = len(spec.contact_links)
    print(f"hand {spec.name}: {spec.dof} joints (6 virtual wrist + {len(spec.finger_joints)} fingers), {L} contact links")
    print(f"observation: hand {2 * spec.dof} + object {L} contact + {L} force + {3 * L} distance + goal {F.GOAL_DIM}"
          f" = {2 * spec.dof + 5 * L + F.GOAL_DIM}; action {spec.dof}")
    print(f"hands: {available_hands()}")
    print(f"tasks: {list(unicross.TASK_IDS)}")
    print(f"modes: {list(F.MODES)}")
    print("target table (paper Table 1):")
    for skill, kinds in F.target_table().items():
        print(f"  {skill:10s} " + "  ".join(f"{k}: {', '.join(v) or '-'}" for k, v in kinds.items()))
    return 0


def _cmd_hands(args) -> int:
    from unicross.robots.hand import available_hands, load_hand
    print(f"{'hand':12s} {'DoF':>4s} {'wrist':>6s} {'fingers':>8s} {'coupled':>8s} {'contact links':>14s} "
          f"{'objects':>8s}  urdf")
    for name in available_hands():
        s = load_hand(name)
        print(f"{name:12s} {s.dof:4d} {6:6d} {len(s.finger_joints):8d} {len(s.mimic):8d} {len(s.contact_links):14d} "
              f"{'x' + format(s.object_scale, 'g'):>8s}  {s.urdf}")
    return 0


def _cmd_grasps(args) -> int:
    import torch
    from unicross.grasps import GraspSet
    from unicross.objects import get_object_set
    from unicross.robots.hand import load_hand
    from unicross.scripted_grasp import finger_census, hold_test, synthesize
    from unicross.rl.ppo import git_commit
    load_hand(args.hand)  # validates
    commit = git_commit()  # the code that makes the grasps (HEAD may move while they are made)
    objs = get_object_set(args.objects, limit=args.limit)
    out = Path(args.out)
    t0 = time.time()
    if args.chain:
        from unicross.rl.expert_grasps import chained_grasps
        if args.expert:
            raise ValueError("--chain and --expert exclude each other (--policy runs the chain's every phase)")
        if not args.policy:
            raise ValueError("--chain needs --policy (e.g. experts:allegro): the policy that runs the chain")
        gs, stats = chained_grasps(args.policy, args.hand, objs, args.chain, args.per_object, seed=args.seed)
    elif args.expert:
        from unicross.rl.expert_grasps import expert_grasps
        from unicross.rl.policy_io import load_policy
        _, ck = load_policy(args.expert)  # fails fast on a missing/invalid checkpoint
        args.hand = ck["hand"]
        gs, stats = expert_grasps(args.expert, objs, args.per_object, seed=args.seed)
    else:
        gs, stats = synthesize(args.hand, objs, args.per_object, seed=args.seed, randomize=args.randomize)
    held, touching = hold_test(args.hand, gs, objs, seconds=2.0, seed=args.seed) if args.hold_test else ([], [])
    found = len(gs)
    census = finger_census(gs, objs, touching, rows=held) if held else None
    if held and not args.keep_all:  # the dataset keeps the grasps that hold
        gs = GraspSet(gs.hand, gs.object_names, gs.data[torch.tensor(held)], gs.source)
    if args.append and out.exists():
        gs = GraspSet.merge([GraspSet.load(out), gs])
    gs.save(out)
    took = time.time() - t0
    summary = dict(produced_by="unicross " + " ".join(sys.argv[1:]) if sys.argv[1:2] == ["grasps"] else None,
                   commit=commit, out=str(out), hand=args.hand, objects=args.objects, num_objects=len(objs),
                   grasps=len(gs), found=found, synthesis_success_rate=round(stats["success_rate"], 4),
                   hold_2s_rate=round(sum(held) / len(held), 4) if held else None,
                   kept=("all" if args.keep_all or not held else "holding"),
                   fingers_after_hold=census, per_object=gs.counts(), seconds=round(took, 1))
    print(f"{'chain' if args.chain else 'expert' if args.expert else 'scripted'} success {stats['success_rate']:.1%}, {found} grasps"
          + (f"; restored grasps holding for 2 s: {sum(held)}/{len(held)} = {sum(held) / len(held):.1%}" if held else "")
          + f"; wrote {len(gs)} grasps ({summary['kept']}) of {len(objs)} objects to {out} in {took:.0f}s")
    for cat, c in (census or {}).items():
        print(f"{cat}: fingers touching the object after the 2 s hold, of {c['grasps']} grasps that held: "
              + ", ".join(f"{f} {n}" for f, n in sorted(c["touching"].items(), key=lambda kv: -kv[1])))
    short = [n for n, c in gs.counts().items() if c < args.per_object]
    if short:
        print(f"{len(short)} object(s) got fewer than {args.per_object} grasps, e.g. {short[:3]}")
    Path(str(out) + ".json").write_text(json.dumps(summary, indent=1))
    return 0


def _cmd_rollout(args) -> int:
    import gymnasium as gym
    import torch
    import unicross
    if args.task not in unicross.TASK_IDS:
        raise ValueError(f"unknown task {args.task!r}; valid: {list(unicross.TASK_IDS)}")
    kwargs = dict(obs_mode="state", sim_backend="physx_cpu", render_backend="none", hand=args.hand,
                  object_limit=args.limit)
    if args.objects:
        kwargs["objects"] = args.objects
    if args.axis:
        from unicross.registry import SKILLS
        skill = next((s for s in SKILLS.values() if s.env_id == args.task and s.axis_kwarg), None)
        if skill is None:
            raise ValueError(f"{args.task} takes no --axis (only {[s.env_id for s in SKILLS.values() if s.axes]} do)")
        kwargs.update(skill.env_kwargs(args.axis))
    if args.grasps:
        kwargs["grasp_dataset"] = args.grasps
    env = gym.make(args.task, **kwargs)
    u = env.unwrapped
    obs, info = env.reset(seed=args.seed)
    g = torch.Generator().manual_seed(args.seed)
    from unicross import formulation as F
    print(f"{args.task}: mode {F.MODES[int(u.mode[0])]}, object {u.env_objects[0].name}")
    totals, steps, t0 = {}, 0, time.time()
    ended = dict(dropped=0, truncated=0)
    for _ in range(args.steps):
        a = torch.zeros(u.hand_spec.dof) if args.zero else torch.rand(u.hand_spec.dof, generator=g) * 2 - 1
        obs, r, term, trunc, info = env.step(a)
        steps += 1
        for k, v in info.items():
            if k.startswith("reward_"):
                totals[k] = totals.get(k, 0.0) + float(v.mean())
        if bool(term.any()) or bool(trunc.any()):
            ended["dropped" if bool(term.any()) else "truncated"] += 1
            obs, info = env.reset()
    dt = time.time() - t0
    print(f"{args.task}: obs {tuple(obs.shape)}, {steps} steps in {dt:.1f}s ({steps / dt:.0f} steps/s); "
          f"episodes ended: {ended['dropped']} by a drop, {ended['truncated']} at their length")
    for k, v in totals.items():
        print(f"  {k:24s} {v / steps:+.4f} per step")
    return 0


def positive(text: str) -> int:
    """argparse type: a whole number >= 1."""
    return _int_at_least(text, 1)


def natural(text: str) -> int:
    """argparse type: a whole number >= 0."""
    return _int_at_least(text, 0)


def _int_at_least(text: str, low: int) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if v < low:
        raise argparse.ArgumentTypeError(f"must be >= {low}, got {v}")
    return v


ABLATIONS = ("no_target_obs", "no_target_action", "no_track_reward", "no_distance", "no_contact")


def parse_sets(items) -> dict:
    """``section.key=value`` strings -> nested dict (values parsed as YAML)."""
    import yaml
    out: dict = {}
    for item in items or []:
        if "=" not in item:
            raise ValueError(f"--set expects section.key=value, got {item!r}")
        path, value = item.split("=", 1)
        node = out
        keys = path.split(".")
        for k in keys[:-1]:
            node = node.setdefault(k, {})
        node[keys[-1]] = _number_or_yaml(value, yaml.safe_load(value))
    return out


def _number_or_yaml(text: str, parsed):
    """YAML 1.1 reads ``1e-5`` (no dot) as a string; a value that reads as a float is a float."""
    if isinstance(parsed, str):
        try:
            return float(text)
        except ValueError:
            pass
    return parsed


def overrides_from(args, **flags) -> dict:
    """``--preset`` overrides, then ``--set`` overrides, then the scale flags (each wins over the
    one before): flags map "section.key" -> value."""
    from unicross.config import deep_merge, load_preset
    overrides = {}
    for name in getattr(args, "preset", None) or []:
        overrides = deep_merge(overrides, load_preset(name), strict=False)
    overrides = deep_merge(overrides, parse_sets(args.set), strict=False)
    for path, value in flags.items():
        if value is not None:
            section, key = path.split(".")
            overrides.setdefault(section, {})[key] = value
    return overrides


def _cmd_train(args) -> int:
    from unicross.rl.ppo import PPOTrainer
    overrides = overrides_from(args, **{"env.num_envs": args.num_envs, "env.backend": args.backend,
                                        "collector.total_frames": args.total_frames})
    for flag in args.ablation or []:
        if flag not in ABLATIONS:
            raise ValueError(f"unknown ablation {flag!r}; valid: {list(ABLATIONS)}")
        overrides.setdefault("env", {}).setdefault("task_config", {}).setdefault("ablation", {})[flag] = True
    if not args.resume and args.skill is None:
        raise ValueError("--skill is required (grasp, relocate, rotate, translate)")
    trainer = PPOTrainer(args.out, args.skill, args.axis, args.hand, overrides=overrides or None,
                         resume=args.resume)
    try:
        summary = trainer.train(max_iterations=args.max_iterations)
    finally:
        trainer.close()
    if trainer.stop_signal is not None:
        return _stopped(trainer, f"iteration {trainer.iteration}, {trainer.frames} frames")
    for k, v in summary.items():
        print(f"{k}: " + ", ".join(f"{a}={b:.4g}" if isinstance(b, float) else f"{a}={b}" for a, b in v.items()))
    print(f"checkpoint: {trainer.run_dir / 'checkpoint.pt'} (iteration {trainer.iteration}, {trainer.frames} frames)")
    return 0


def _stopped(trainer, where: str) -> int:
    """One line for a run stopped by SIGINT/SIGTERM (saved at the end of its iteration); the exit
    status a shell gives a process killed by that signal."""
    import signal
    name = signal.Signals(trainer.stop_signal).name
    print(f"stopped by {name}: saved {trainer.run_dir / 'checkpoint.pt'} ({where}); continue with --resume",
          file=sys.stderr)
    return 128 + int(trainer.stop_signal)


def _cmd_export(args) -> int:
    """The acting part of a run's checkpoint (policy + observation statistics) and a JSON sidecar."""
    import os
    import platform
    from unicross.evaluation import read_results
    from unicross.report import cpu_model
    from unicross.rl.policy_io import export_policy
    run = Path(args.run)
    ckpt = run / "checkpoint.pt" if run.is_dir() else run
    if not ckpt.exists():
        raise FileNotFoundError(f"no checkpoint at {ckpt}")
    sidecar = dict(commands=args.command or [], hardware=dict(machine=platform.machine(), cpus=os.cpu_count(),
                                                               processor=cpu_model(),
                                                               python=platform.python_version()))
    from unicross.rl.policy_io import read_torch_file
    ck = read_torch_file(ckpt, "checkpoint")
    sidecar["train_wall_s"] = round(float(ck.get("wall_s", 0.0)), 1)
    if ck.get("clone_of"):  # benchmarks/gait_clone.py: a network fitted to a scripted gait, not PPO
        sidecar["kind"] = "dagger clone of a scripted gait"
    for f in args.eval or []:
        e = read_results(f)
        sidecar.setdefault("evaluations", []).append(dict(file=str(f), objects=e.get("objects"), limit=e.get("limit"),
                                                          trials_per_object=e.get("trials_per_object"),
                                                          seed=e.get("seed"), summaries=e.get("summaries")))
    out = export_policy(ckpt, args.out, sidecar)
    print(f"wrote {out} ({out.stat().st_size / 1e6:.2f} MB) and {out.with_suffix('.json')}")
    return 0


def _cmd_audit(args) -> int:
    from unicross.audit import ascent, audit, behaviours, first_dip, format_rows
    overrides = overrides_from(args)
    if args.ascent:
        rows = ascent(args.skill, args.axis, objects=args.objects, limit=args.limit, seeds=args.seeds,
                      hand=args.hand, ppo_overrides=overrides or None)
    else:
        rows = audit(args.skill, args.axis, args.objects, args.limit, args.seeds, args.hand,
                     ppo_overrides=overrides or None, only=args.only.split(",") if args.only else None)
    print(format_rows(rows))
    if args.ascent:
        dip = first_dip(rows)
        print("the return rises along the whole path" if dip is None else f"the return first falls at {dip}")
    else:
        ranked = [r.behaviour for r in rows]
        ref = next(iter(behaviours(args.skill)))  # each skill lists its successful reference first
        if ref in ranked:
            print(f"successful reference ({ref}) ranks {1 + ranked.index(ref)} of {len(rows)}")
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps([r.__dict__ for r in rows], indent=1))
    return 0


def default_label(policy: str) -> str:
    """Table label of ``--policy``: a checkpoint file by its name, anything else ('zero',
    'reference@0.75', 'allegro/grasp') as given."""
    return Path(policy).stem if policy.endswith(".pt") else policy


def _cmd_eval(args) -> int:
    from unicross.config import parse_sim_overrides
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    protocols = list(E.PROTOCOLS) if args.protocol == "all" else args.protocol.split(",")
    bad = [p for p in protocols if p not in E.PROTOCOLS]
    if bad:
        raise ValueError(f"unknown protocol(s) {bad}; valid: {list(E.PROTOCOLS)} or 'all'")
    from unicross.registry import SKILLS
    axes = args.axis.split(",") if args.axis else None
    with_axes = [p for p in protocols if SKILLS[p].axes]
    if axes:
        if not with_axes:
            raise ValueError(f"--axis {args.axis}: none of the protocols {protocols} has axes (rotate and translate do)")
        for p in with_axes:
            bad = [a for a in axes if a not in SKILLS[p].axes]
            if bad:
                raise ValueError(f"--axis {args.axis}: {bad} are not axes of protocol {p!r}: {list(SKILLS[p].axes)}")
    if E.reference_fraction(args.policy) is not None:
        from unicross.audit import PHYSICAL_REFERENCES
        missing = [f"{p} {a}" for p in protocols for a in ((axes or SKILLS[p].axes) if SKILLS[p].axes else (None,))
                   if (p, a) not in PHYSICAL_REFERENCES]
        if missing:
            raise ValueError(f"--policy {args.policy}: no physical reference for {missing}; known: "
                             f"{sorted(PHYSICAL_REFERENCES)} (e.g. --protocol translate --axis z+)")
    objs = get_object_set(args.objects, limit=args.limit)
    _, desc = E.resolve_policy(args.policy, args.hand, seed=args.seed)  # checks the checkpoint before simulating
    if desc["kind"] == "gait":  # a gait does one mode: it is evaluated on that mode only
        skill, _, axis = desc["mode"].partition("_")
        if protocols != [skill] or axes != [axis]:
            raise ValueError(f"--policy {args.policy} is a gait for {desc['mode']}: evaluate it with "
                             f"--protocol {skill} --axis {axis}")
    ablation = desc.get("ablation")
    if args.ablation:
        bad = [f for f in args.ablation if f not in ABLATIONS]
        if bad:
            raise ValueError(f"unknown ablation {bad}; valid: {list(ABLATIONS)}")
        trained = sorted(k for k, v in (ablation or {}).items() if v)
        if desc["kind"] == "checkpoint" and trained != sorted(set(args.ablation)):
            raise ValueError(f"checkpoint {args.policy} was trained with ablation {trained or 'none'}; "
                             f"it is evaluated with the switches it was trained with (drop --ablation)")
        ablation = {f: True for f in args.ablation}
    sim = dict(desc.get("sim") or {}, **parse_sim_overrides(args.sim))  # a checkpoint's own physics, then --sim
    label = args.label or default_label(args.policy)
    result = dict(label=label, policy=desc, objects=args.objects, limit=args.limit, hand=args.hand,
                  trials_per_object=args.trials_per_object, seed=args.seed, axes=axes, disturb=args.disturb,
                  original=args.original, randomize=args.randomize, ablation=ablation or {}, summaries={}, trials={})
    if sim:  # recorded only where the physics is not configs/task.yaml's
        result["sim"] = sim
    out = Path(args.out)
    if args.resume and out.is_file():  # the protocols a stopped evaluation finished are kept
        done = json.loads(out.read_text())
        differ = [k for k in result if k not in ("label", "summaries", "trials") and done.get(k) != result[k]]
        if differ:
            raise ValueError(f"--resume: {out} was evaluated with other settings ({', '.join(differ)}); "
                             f"use another --out or the same settings")
        result["trials"], result["summaries"] = done["trials"], done["summaries"]
    _write_eval(out, result)  # before simulating: an --out that cannot be written fails now
    for p in protocols:
        if p in result["trials"]:
            print(f"eval {p}: kept from {out} ({len(result['trials'][p])} trials)")
            continue
        trials = E.run_protocol_workers(p, args.policy, objs, hand=args.hand, workers=args.workers, seed=args.seed,
                                        trials_per_object=args.trials_per_object, disturb=args.disturb,
                                        randomize=args.randomize, grasp_dataset=args.grasps, original=args.original,
                                        videos=args.videos,
                                        video_dir=Path(args.out).parent / (Path(args.out).stem + "_videos"),
                                        ablation=ablation, sim=sim or None,
                                        **({"axes": axes} if axes and p in with_axes else {}))
        result["trials"][p] = trials
        result["summaries"][p] = E.summarize(p, trials)
        _write_eval(out, result)  # each finished protocol is on disk before the next starts
    table = _write_eval(out, result)
    print(table)
    print(f"wrote {out} and {markdown_path(out)}")
    return 0


def markdown_path(out: Path) -> Path:
    """The markdown table beside an evaluation's JSON ``out``: ``e.json`` -> ``e.md``, ``heldout`` ->
    ``heldout.md``, and ``lookahead1.5`` -> ``lookahead1.5.md`` (not ``lookahead1.md``, which
    another run's table may own)."""
    return out.with_suffix(".md") if out.suffix == ".json" else out.with_name(out.name + ".md")


def _write_eval(out: Path, result: dict) -> str:
    """Writes an evaluation's JSON and markdown table atomically; returns the table."""
    from unicross import evaluation as E
    from unicross.config import atomic_write
    if out.is_dir():
        raise ValueError(f"--out {out} is a directory; give a file name such as {out / 'eval.json'}")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        raise ValueError(f"--out {out}: {out.parent} is not a directory") from None
    table = E.markdown_table({result["label"]: result["summaries"]}) if result["summaries"] else ""
    for path, text in ((out, json.dumps(result, indent=1)), (markdown_path(out), table + "\n")):
        try:
            atomic_write(path, lambda tmp: tmp.write_text(text))
        except OSError as e:
            raise ValueError(f"cannot write --out {out}: {e.strerror}") from None
    return table


def _cmd_report(args) -> int:
    from unicross import evaluation as E
    if args.paper:
        return _cmd_report_paper(args)
    if not args.files:
        raise ValueError("report needs eval JSON files, or --paper to evaluate the shipped checkpoints")
    rows: dict = {}
    for f in args.files:
        r = E.read_results(f)
        label = r["label"] + (" (Dis.)" if r.get("disturb") else "") + (" (Ori.)" if r.get("original") else "")
        rows.setdefault(label, {}).update(r["summaries"])
    table = E.markdown_table(rows)
    if args.title:
        table = f"**{args.title}**\n\n" + table
    print(table)
    if args.out:
        Path(args.out).write_text(table + "\n")
    return 0


def _cmd_report_paper(args) -> int:
    from unicross.config import parse_sim_overrides
    from unicross.report import paper_report
    if args.files:
        raise ValueError("report --paper evaluates the shipped checkpoints; it takes no eval JSON files")
    if args.trials_per_object < 1 or args.limit < 0 or args.workers < 1 or args.min_trials < 0:
        raise ValueError("--trials-per-object and --workers must be >= 1, --limit and --min-trials >= 0 "
                         "(--limit 0: every object)")
    sim = parse_sim_overrides(args.sim)
    out = Path(args.out or "docs/results.md")
    out.parent.mkdir(parents=True, exist_ok=True)
    if out.is_dir():
        raise ValueError(f"--out {out} is a directory; give a .md file")
    with open(out, "a"):  # writable, checked before any simulation
        pass
    argv = ["report", "--paper", "--hand", args.hand, "--limit", str(args.limit), "--trials-per-object",
            str(args.trials_per_object), "--min-trials", str(args.min_trials), "--workers", str(args.workers),
            "--seed", str(args.seed)] + [a for pair in args.sim or () for a in ("--sim", pair)] + ["--out", str(out)]
    paper_report(str(out), argv, hand=args.hand, limit=args.limit or None, trials=args.trials_per_object,
                 min_trials=args.min_trials, workers=args.workers, seed=args.seed, sim=sim or None)
    print(f"wrote {out}")
    return 0


def _cmd_render(args) -> int:
    from unicross.render import render
    try:
        w, h = (int(v) for v in args.size.lower().split("x"))
        assert w > 0 and h > 0
    except (ValueError, AssertionError):
        raise ValueError(f"--size takes WIDTHxHEIGHT in pixels, e.g. 640x480; got {args.size!r}") from None
    out = render(args.trajectory, args.out, camera=args.camera, width=w, height=h, fps=args.fps,
                 renderer=args.renderer, every=args.every)
    print(f"wrote {out}")
    return 0


def _cmd_distill(args) -> int:
    from unicross.rl.dagger import DAggerTrainer
    overrides = overrides_from(args, **{"env.num_envs": args.num_envs, "env.backend": args.backend,
                                        "optim.epochs": args.epochs})
    trainer = DAggerTrainer(args.out, args.experts, overrides=overrides or None, resume=args.resume)
    try:
        last = trainer.train()
    finally:
        trainer.close()
    if trainer.stop_signal is not None:
        return _stopped(trainer, f"epoch {trainer.epoch}, {trainer.frames} frames")
    print(", ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in last.items()))
    print(f"student checkpoint: {trainer.run_dir / 'checkpoint.pt'} (epoch {trainer.epoch})")
    return 0


def _cmd_chain(args) -> int:
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    from unicross.config import parse_sim_overrides
    from unicross.tasks.chain import parse_sequence
    if args.sequence:
        parse_sequence(args.sequence)  # validates before any simulation
    overrides = parse_sim_overrides(args.sim)
    objs = get_object_set(args.objects, limit=args.limit)
    policy, desc = E.resolve_policy(args.policy, args.hand, seed=args.seed)
    sim = dict(desc.get("sim") or {}, **overrides)  # the policy's own physics, then --sim
    videos = 1 if args.video else 0
    video_dir = Path(args.video).parent if args.video else None
    trials = E.run_chain(policy, objs, args.sequence, hand=args.hand, trials_per_object=args.trials_per_object,
                         seed=args.seed, videos=videos, video_dir=video_dir, sim=sim or None)
    for t in trials:
        phases = ", ".join(f"{m}: {'ok' if s else 'FAIL'}" for m, s in zip(t["sequence"], t["phase_success"]))
        print(f"{t['object']} trial {t['trial']}: {phases} -> {'SUCCESS' if t['overall'] else 'failure'}")
    summary = E.summarize_chain(trials)
    print(E.chain_table(summary))
    if args.video and trials:
        made = sorted(video_dir.glob(f"chain_{trials[0]['object']}_0.mp4"))
        if made:
            made[0].replace(args.video)
            print(f"video: {args.video}")
    if args.out:
        extra = dict(sim=sim) if sim else {}  # recorded only where it differs from configs/task.yaml's
        Path(args.out).write_text(json.dumps(dict(policy=desc, trials=trials, summary=summary, **extra), indent=1))
    return 0


def main(argv=None) -> int:
    from unicross.config import load_config
    from unicross.registry import SKILLS
    axes_help = "; ".join(f"{s.name}: {','.join(s.axes)}" for s in SKILLS.values() if s.axes)
    p = argparse.ArgumentParser(prog="unicross", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("info", help="print task ids, sizes and the target table")
    s.add_argument("--hand", default="allegro")
    s.set_defaults(fn=_cmd_info)
    s = sub.add_parser("hands", help="list the registered hands with their DoF")
    s.set_defaults(fn=_cmd_hands)
    s = sub.add_parser("grasps", help="build a grasp-state dataset (grasp expert, or the scripted synthesiser)")
    s.add_argument("--expert", default=None, help="grasp expert checkpoint (default: the scripted synthesiser)")
    s.add_argument("--chain", default=None,
                   help="record the states where a chain SEQUENCE (e.g. grasp,relocate) run by --policy leaves the "
                        "hand instead (rows marked keep_wrist: in-hand starts from them keep that wrist pose); with "
                        "--append, chain-aware starts for an in-hand mode's training")
    s.add_argument("--policy", default=None, help="with --chain: the policy that runs it (experts:allegro, a student, ...)")
    s.add_argument("--objects", default="train", help="object set (train, test-wrappable, unseen, mesh:<file>, ...)")
    s.add_argument("--limit", type=positive, default=None, help="first N objects of each (category, type) group")
    s.add_argument("--per-object", type=positive, default=5)
    s.add_argument("--hand", default="allegro")
    s.add_argument("--out", required=True)
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("--append", action="store_true", help="merge into an existing dataset at --out")
    s.add_argument("--no-randomize", dest="randomize", action="store_false",
                   help="synthesise at nominal mass/friction (default: randomised, as in training)")
    s.add_argument("--keep-all", action="store_true",
                   help="keep grasps that fail the 2 s hold test too (default: keep those that hold)")
    s.add_argument("--no-hold-test", dest="hold_test", action="store_false",
                   help="skip restoring every grasp and checking it holds for 2 s")
    s.set_defaults(fn=_cmd_grasps)
    s = sub.add_parser("rollout", help="run random (or zero) actions in a task and print reward terms")
    s.add_argument("--task", default="UniCross-Grasp-v1")
    s.add_argument("--axis", default=None, help="rotate axis / translate direction")
    s.add_argument("--objects", default=None)
    s.add_argument("--limit", type=positive, default=2)
    s.add_argument("--grasps", default=None, help="grasp dataset (default: the shipped one)")
    s.add_argument("--hand", default="allegro")
    s.add_argument("--steps", type=positive, default=200)
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("--zero", action="store_true", help="zero actions instead of random ones")
    s.set_defaults(fn=_cmd_rollout)
    s = sub.add_parser("eval", help="run the paper's evaluation protocols; writes JSON (every trial) and a table")
    s.add_argument("--policy", required=True,
                   help="checkpoint path, or zero | random | scripted-grasp | scripted-relocate | reference[@FRACTION] "
                        "(the physical reference: translate z+ opens the fingers, z- curls the index) | seq:SPEC (a finger sequence, "
                        "unicross.sequences, e.g. seq:index:2:0.05:0:1000+ring:2:0.05:@index:0.9) | gait:LOG or gait:allegro/rotate_y- (the best finger gait "
                        "of a benchmarks/gait_search.py log, or a shipped one, run until the mode is done, then holding) | "
                        "experts:DIR or experts:allegro (one expert per mode, DIR/<mode>/checkpoint.pt as distill reads them "
                        "or the hand's shipped ones, each env acted on by its mode's expert)")
    s.add_argument("--protocol", default="all", help="grasp, relocate, rotate, translate (comma list) or all")
    s.add_argument("--objects", default="test", help="object set: train | test | unseen (| -wrappable/-elongated | mesh:<file>)")
    s.add_argument("--limit", type=positive, default=None, help="first N objects per (category, type) group")
    s.add_argument("--trials-per-object", type=positive, default=load_config("eval")["trials_per_object"],
                   help="starts per object and axis (default: configs/eval.yaml, the paper's 25)")
    s.add_argument("--axis", default=None,
                   help="rotate/translate: only these axes (comma list, e.g. z+ or x+,x-; default: all of the "
                        "protocol's); protocols without axes ignore it. " + axes_help)
    s.add_argument("--disturb", action="store_true", help="constant random force U[0, 10 m g] on the object")
    s.add_argument("--original", action="store_true",
                   help="baselines' original settings: no table (grasp), palm up and fixed wrist (rotate/translate)")
    s.add_argument("--randomize", action="store_true", help="keep domain randomisation on during evaluation")
    s.add_argument("--grasps", default=None, help="grasp-state dataset (default: the shipped one)")
    s.add_argument("--hand", default="allegro")
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("--label", default=None, help="row label in tables (default: the policy name)")
    s.add_argument("--videos", type=natural, default=0, help="record and render the first K trials of each protocol")
    s.add_argument("--ablation", action="append", metavar="FLAG",
                   help="evaluate zero/scripted policies under one of the paper's ablations (repeatable; a "
                        "checkpoint always runs with the switches it was trained with): " + ", ".join(ABLATIONS))
    s.add_argument("--sim", action="append", metavar="KEY=VALUE",
                   help="physics other than configs/task.yaml's sim section (repeatable), e.g. "
                        "solver_position_iterations=8 (the default before 2026-12-04); a checkpoint trained under "
                        "other physics runs under its own unless this says otherwise; recorded in --out")
    s.add_argument("--workers", type=positive, default=1,
                   help="processes to split the objects over (same trials for any number; one env per process)")
    s.add_argument("--out", required=True, help="JSON with every trial (+ .md table), written after each protocol")
    s.add_argument("--resume", action="store_true",
                   help="finish an evaluation in --out that stopped: keep its finished protocols, run the rest")
    s.set_defaults(fn=_cmd_eval)
    s = sub.add_parser("report", help="assemble eval JSON files into the paper's table layout; --paper: evaluate "
                                      "the shipped checkpoints and write the paper's tables (docs/results.md)")
    s.add_argument("files", nargs="*")
    s.add_argument("--title", default=None)
    s.add_argument("--out", default=None, help="markdown file (--paper: default docs/results.md)")
    s.add_argument("--paper", action="store_true",
                   help="evaluate every shipped checkpoint of --hand with the paper's protocols and write the tables")
    s.add_argument("--hand", default="allegro")
    s.add_argument("--limit", type=natural, default=10, help="--paper: first N objects per (category, shape) group (0: all, the paper's full sets)")
    s.add_argument("--trials-per-object", type=positive, default=3, help="--paper: trials per object and axis")
    s.add_argument("--min-trials", type=natural, default=100,
                   help="--paper: raise the trials per object of a cell until it has at least N trials (0: off)")
    s.add_argument("--workers", type=positive, default=1, help="--paper: processes per evaluation")
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("--sim", action="append", metavar="KEY=VALUE",
                   help="--paper: every cell under physics other than configs/task.yaml's sim section (repeatable), "
                        "as `unicross eval --sim`; printed in the command at the top")
    s.set_defaults(fn=_cmd_report)
    s = sub.add_parser("render", help="render a trajectory file to .mp4/.gif/.png (CPU: pyrender+EGL; GPU: SAPIEN)")
    s.add_argument("trajectory")
    s.add_argument("--out", required=True, help="video.mp4, anim.gif or still.png (last frame)")
    s.add_argument("--camera", default="front", help="front | side | top | follow")
    s.add_argument("--size", default="640x480")
    s.add_argument("--fps", type=positive, default=None)
    s.add_argument("--every", type=positive, default=1, help="render every k-th step")
    s.add_argument("--renderer", default="auto", help="auto | pyrender | sapien")
    s.set_defaults(fn=_cmd_render)
    s = sub.add_parser("distill", help="DAgger: distil the ten experts into one student; resumable")
    s.add_argument("--experts", default=None, help="directory with <mode>/checkpoint.pt for all ten modes")
    s.add_argument("--out", required=True, help="run directory (student checkpoint.pt, metrics.jsonl, replay/)")
    s.add_argument("--num-envs", type=positive, default=None)
    s.add_argument("--backend", choices=["physx_cpu", "physx_cuda"], default=None)
    s.add_argument("--epochs", type=positive, default=None)
    s.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE", help="override configs/dagger.yaml")
    s.add_argument("--resume", action="store_true")
    s.set_defaults(fn=_cmd_distill)
    s = sub.add_parser("chain", help="long-horizon skill chaining with one policy; prints per-phase outcomes")
    s.add_argument("--policy", required=True, help="student/expert checkpoint, zero | random, or experts:DIR | experts:allegro "
                        "(the per-mode experts, switched at each phase: the teachers' chain)")
    s.add_argument("--sequence", default=None,
                   help="e.g. grasp,relocate,rotate:x+ (default: the paper's protocol, random in-hand axis)")
    s.add_argument("--objects", default="test")
    s.add_argument("--limit", type=positive, default=1)
    s.add_argument("--trials-per-object", type=positive, default=1)
    s.add_argument("--hand", default="allegro")
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("--video", default=None, help="record the first trial and render it to this .mp4")
    s.add_argument("--sim", action="append", metavar="KEY=VALUE",
                   help="physics other than configs/task.yaml's sim section (repeatable), as `unicross eval --sim`")
    s.add_argument("--out", default=None, help="JSON with every trial")
    s.set_defaults(fn=_cmd_chain)
    s = sub.add_parser("export", help="ship a run: policy weights + normaliser only, with a JSON sidecar")
    s.add_argument("run", help="run directory (or checkpoint.pt)")
    s.add_argument("--out", required=True, help="e.g. unicross/checkpoints/allegro/grasp.pt")
    s.add_argument("--command", action="append", help="a command that produced the run (repeat, in order)")
    s.add_argument("--eval", action="append", help="an eval result written by `unicross eval` to record (.json or .json.gz)")
    s.set_defaults(fn=_cmd_export)
    s = sub.add_parser("audit", help="reward audit: discounted, scaled returns of reference behaviours, ranked")
    s.add_argument("--skill", choices=list(SKILLS), default="grasp")
    s.add_argument("--axis", default=None, help=axes_help)
    s.add_argument("--objects", default=None, help="object set (default: the skill's training set)")
    s.add_argument("--limit", type=positive, default=2, help="first N objects per (category, type) group")
    s.add_argument("--seeds", type=positive, default=3, help="episodes per object and behaviour")
    s.add_argument("--only", default=None, help="comma list of behaviours (default: all)")
    s.add_argument("--ascent", action="store_true",
                   help="instead: the mode's physical reference at fractions of its rate, in order (translate z+ and z-)")
    s.add_argument("--hand", default="allegro")
    s.add_argument("--preset", action="append", metavar="NAME", help="configs/presets/NAME.yaml (e.g. paper_reward)")
    s.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE", help="override configs/ppo.yaml")
    s.add_argument("--out", default=None, help="JSON with the rows")
    s.set_defaults(fn=_cmd_audit)
    s = sub.add_parser("train", help="train one expert with PPO (TorchRL); resumable")
    s.add_argument("--preset", action="append", metavar="NAME",
                   help="configs/presets/NAME.yaml: paper_gpu (the paper's PPO values), paper_reward (its exact reward)")
    s.add_argument("--skill", choices=list(SKILLS), default=None)
    s.add_argument("--axis", default=None, help=axes_help)
    s.add_argument("--direction", dest="axis", help=argparse.SUPPRESS)
    s.add_argument("--hand", default=None, help="default allegro (a resumed run keeps its own)")
    s.add_argument("--out", required=True, help="run directory (checkpoint, metrics.csv, metrics.jsonl, tb/)")
    s.add_argument("--num-envs", type=positive, default=None)
    s.add_argument("--total-frames", type=positive, default=None)
    s.add_argument("--backend", choices=["physx_cpu", "physx_cuda"], default=None)
    s.add_argument("--max-iterations", type=positive, default=None, help="stop (and checkpoint) after this many iterations")
    s.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE", help="override configs/ppo.yaml")
    s.add_argument("--ablation", action="append", metavar="FLAG",
                   help="one of the paper's ablations (repeatable): " + ", ".join(ABLATIONS))
    s.add_argument("--resume", action="store_true", help="continue the run in --out from its checkpoint")
    s.set_defaults(fn=_cmd_train)
    try:
        args = p.parse_args(argv)
    except SystemExit as e:  # --help (0) or a usage error (2, said by argparse): a status, as every command returns
        return int(e.code or 0)
    try:
        return args.fn(args)
    except (ValueError, FileNotFoundError, FileExistsError, KeyError, RuntimeError) as e:  # incl. RenderUnavailable
        print(f"unicross {args.cmd}: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # a second Ctrl-C (the first stops training at the end of its iteration)
        print(f"unicross {args.cmd}: interrupted; the last checkpoint written stays as it was", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
