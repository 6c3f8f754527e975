"""DAgger of a scripted finger gait into a network policy: can a policy that sees only the
observation do what a gait does with its clock and its privileged stop?

A shipped rotate gait (:mod:`unicross.gaits`) acts from the control step, the start command and
the object's accumulated rotation (read from the task's state); the UniCross policy network sees
s^h, s^o and g. This script labels states with the gait and fits the network to the labels
(DAgger, Ross et al. 2011): round 0 rolls the gait out, every later round rolls the current network
out (its mean action) and the gait labels the states the network visits (the gait's label is a
step toward its own trajectory from the current joint command, and its stop follows the object's
actual rotation, so it is defined on any state); the network is refitted on everything gathered
(MSE on the action mean, the observation normaliser fitted to the data; ``fresh_mse`` in the log is
the network's error on a round's new states before it is refitted on them, i.e. on states it has not
been fitted to, and ``mse`` its error on all the data after the refit); the network kept is the
one whose own rollouts succeeded most often (with ``--beta``, DAgger's mixture: in round r the
gait takes over a fraction beta**r of the network's steps, and only the last round, the network
alone, selects). Rollouts run the rotate
protocol on training objects (400 steps, the evaluation's conditions unless ``--randomize``),
split over ``--workers`` processes; each round prints the network's own success rate.

The result is a policy checkpoint in the shipped format (``unicross eval --policy OUT/policy.pt``),
and a PPO run can start from it (``unicross train ... --set model.init_policy=OUT/policy.pt``):

    python benchmarks/gait_clone.py --gait allegro/rotate_y- --limit 8 --trials 2 --rounds 5 \
        --out docs/runs/gait_clone/rotate_y-

``--sequence SPEC --mode MODE`` clones a finger sequence (:mod:`unicross.sequences`) on MODE's protocol
the same way; a sequence whose terms are state-triggered is a function of the observation (up to the
clock windows it uses), e.g. translate z-'s index pull with the ring finger joining once the index has curled:

    python benchmarks/gait_clone.py --sequence "index:2:0.05:0:1000+ring:2:0.05:@index:0.9" --mode translate_z- \
        --limit 8 --trials 2 --rounds 4 --out docs/runs/translate_zm_reference/clone_ring
"""
from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import torch

from unicross import formulation as F


def _rollouts(gait: str, hand: str, objects: str, limit: int, trials: int, seed: int, randomize: bool,
              student, shard, beta: float = 0.0, privileged_q0: bool = False, clock: bool = False,
              history: int = 0, sequence: str = None, mode: str = None, grasps: str = None,
              accumulated: bool = False, sim: dict = None, drift: float = 0.0) -> tuple:
    """One worker's share: (obs dict of [N, d], labels [N, A], trials) of the protocol of the gait's mode
    on its objects, the gait acting (``student`` None) or the student's mean acting while the gait labels
    (with ``sequence``, a finger sequence of :mod:`unicross.sequences` on ``mode``'s protocol instead);
    with ``beta`` > 0 the gait's own action is taken instead at that fraction of the steps (each env
    and step drawn on its own: DAgger's mixture policy). ``grasps``: the grasp-state dataset the episodes
    start from (None: the hand's shipped one). ``sim``: physics overrides of ``configs/task.yaml``'s ``sim``.
    ``drift`` > 0 (with a ``student``): each episode draws one constant offset per finger action, Gaussian with this
    std (action units), added to every action the episode takes, so the states drift as a student's small steady
    bias drifts them; the labels stay the teacher's."""
    torch.set_num_threads(1)
    import unicross  # noqa: F401  (registers the tasks)
    from unicross import evaluation as E
    from unicross.gaits import best_gait, gait_mode, gait_period, make_gait_policy, resolve_gait
    from unicross.objects import get_object_set
    from unicross.rl.env import split_obs
    if sequence:
        from unicross.sequences import make_sequence_policy
        teacher, period = make_sequence_policy(sequence), None
    else:
        teacher = make_gait_policy(gait)
        mode = gait_mode(teacher.gait_row)
        period = gait_period(best_gait(resolve_gait(gait))[0])
    skill, axis = mode.split("_")
    keys = ("hand", "object", "goal")
    rows = {k: [] for k in keys}
    labels = []
    mix = torch.Generator().manual_seed(seed + 104729 * shard[0])
    offset = {}

    q0 = {}
    prev = {}

    def policy(obs, u):
        label = teacher(obs, u)
        parts = split_obs(obs)
        if history:  # diagnosis only: the last `history` control steps' s^h appended (the first step's own before it)
            now = parts[0]
            if int(u.elapsed_steps[0]) == 0:
                prev["h"] = now.repeat(1, history)
            before = prev["h"]
            prev["h"] = torch.cat([now, before[:, :-now.shape[-1]]], -1)
            parts = (torch.cat([now, before], -1),) + tuple(parts[1:])
        if privileged_q0:  # diagnosis only: the episode's start command appended to the hand state
            if int(u.elapsed_steps[0]) == 0:
                q0["q"] = u.command[:, 6:].clone()
            parts = (torch.cat([parts[0], q0["q"]], -1),) + tuple(parts[1:])
        if clock:  # diagnosis only: the gait's clock (its phase at this step) appended to the hand state
            th = 2 * torch.pi * u.elapsed_steps.float()[:, None] / period
            parts = (torch.cat([parts[0], torch.sin(th), torch.cos(th)], -1),) + tuple(parts[1:])
        if accumulated:  # diagnosis only: the motion accumulated along the axis so far, over the success threshold
            sc = u.cfg["success"]
            done = u.rot_acc / sc["rotate_angle"] if skill == "rotate" else u.trans_acc / sc["translate_dist"]
            parts = (torch.cat([parts[0], done[:, None]], -1),) + tuple(parts[1:])
        for k, x in zip(keys, parts):
            rows[k].append(x.clone())
        labels.append(label.clone())
        if student is None:
            return label
        with torch.no_grad():
            act = student(*parts)[0].clamp(-1.0, 1.0)
        if beta > 0:
            gait_steps = torch.rand(act.shape[0], 1, generator=mix) < beta
            act = torch.where(gait_steps, label, act)
        if drift > 0:
            if int(u.elapsed_steps[0]) == 0:
                offset["a"] = torch.zeros_like(act)
                offset["a"][:, 6:] = drift * torch.randn(act.shape[0], act.shape[1] - 6, generator=mix)
            act = (act + offset["a"]).clamp(-1.0, 1.0)
        return act

    out = E.run_protocol(skill, policy, get_object_set(objects, limit=limit), hand=hand, trials_per_object=trials,
                         seed=seed, randomize=randomize, axes=[axis], progress=False, shard=shard,
                         grasp_dataset=grasps, sim=sim)
    return {k: torch.cat(v) for k, v in rows.items()}, torch.cat(labels), out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    teacher = ap.add_mutually_exclusive_group(required=True)
    teacher.add_argument("--gait", help="a shipped gait (allegro/rotate_y-) or a gait_search log, with "
                         "options after commas (allegro/rotate_y-,tracking=phase,lookahead=1.5: unicross.gaits)")
    teacher.add_argument("--sequence", help="instead: a finger sequence (unicross.sequences), e.g. "
                         "index:2:0.05:0:400+ring:2:0.05:@index:0.9, on the protocol of --mode")
    ap.add_argument("--mode", default="translate_z-", help="the mode of --sequence (a gait names its own)")
    ap.add_argument("--hand", default="allegro")
    ap.add_argument("--objects", default="train")
    ap.add_argument("--limit", type=int, default=8, help="first N objects per group of --objects")
    ap.add_argument("--trials", type=int, default=2, help="episodes per object per round")
    ap.add_argument("--rounds", type=int, default=5, help="round 0: the gait acts; then the network")
    ap.add_argument("--epochs", type=int, default=30, help="passes over the aggregated data after each round")
    ap.add_argument("--batch", type=int, default=512)
    ap.add_argument("--lr", type=float, default=1e-3)
    ap.add_argument("--weight-decay", type=float, default=0.0, help="AdamW's decoupled weight decay (0: Adam)")
    ap.add_argument("--obs-std-min", type=float, default=None,
                    help="model.obs_std_min of the network (floor of the std its inputs are divided by; "
                         "default: configs/ppo.yaml's); stored in the checkpoint")
    ap.add_argument("--beta", type=float, default=0.0,
                    help="DAgger's mixture: in round r the gait acts at beta**r of the network's steps (0: never)")
    ap.add_argument("--privileged-q0", action="store_true",
                    help="diagnosis only: the network also sees the episode's start command (the gait's centre); "
                         "its checkpoint does not fit the UniCross observation and is not written")
    ap.add_argument("--clock", action="store_true",
                    help="diagnosis only: the network also sees the gait's clock (sin and cos of its phase at the "
                         "control step); its checkpoint does not fit the UniCross observation and is not written")
    ap.add_argument("--history", type=int, nargs="?", const=1, default=0, metavar="N",
                    help="diagnosis only: the network also sees the previous N control steps' s^h (joint readings "
                         "and command; N = 1 without a number), as HORA's proprioceptive history (30 steps there); "
                         "its checkpoint does not fit the UniCross observation and is not written")
    ap.add_argument("--progress", action="store_true",
                    help="diagnosis only: the network also sees the motion accumulated along the axis so far over the "
                         "success threshold (what a gait's stop reads; a memory of the episode the observation lacks); "
                         "its checkpoint does not fit the UniCross observation and is not written")
    ap.add_argument("--drift", type=float, default=0.0, metavar="SIGMA",
                    help="in the rounds the network acts (not the last, which measures it): a constant offset per "
                         "finger action and episode, N(0, SIGMA^2) in action units, added to the actions taken, so the "
                         "data holds the teacher's labels on states a student's small steady bias drifts to (0: none)")
    ap.add_argument("--randomize", action="store_true", help="training's randomisation (default: the evaluation's conditions)")
    ap.add_argument("--grasps", default=None, help="grasp-state dataset the episodes start from (default: the shipped one)")
    ap.add_argument("--heldout", type=int, default=0, metavar="LIMIT",
                    help="then roll the kept network out alone on the first LIMIT objects per group of "
                         "--heldout-objects x 3 trials, seed 0 (the trials of `unicross eval ... --limit LIMIT "
                         "--trials-per-object 3 --seed 0`; 20: the 120-trial held-out cell), written to "
                         "OUT/heldout.json; also for diagnosis runs, whose networks no checkpoint can hold (0: skip)")
    ap.add_argument("--heldout-objects", default="test")
    ap.add_argument("--sim", action="append", metavar="KEY=VALUE",
                    help="physics other than configs/task.yaml's sim section (repeatable), e.g. "
                         "solver_position_iterations=8 (the default before 2026-12-04); recorded in the checkpoint, whose evaluation then runs under it")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", required=True)
    args = ap.parse_args(argv)

    import unicross  # noqa: F401
    from unicross.config import load_config, parse_sim_overrides
    from unicross.gaits import gait_mode, make_gait_policy
    from unicross.grasps import grasp_dataset_file
    from unicross.metrics import wilson_interval
    from unicross.rl.models import make_models
    from unicross.rl.ppo import env_kwargs_for
    from unicross.rl.runner import git_commit
    from unicross import registry as R
    if args.sequence:  # a bad sequence, mode, gait or option fails before any simulation
        from unicross.sequences import parse_sequence
        parse_sequence(args.sequence)
        if args.mode not in F.MODES or "_" not in args.mode:
            ap.error(f"--mode {args.mode!r}: an in-hand mode, one of {[m for m in F.MODES if '_' in m]}")
        if args.clock:
            ap.error("--clock needs a gait (its period)")
        mode = args.mode
    else:
        mode = gait_mode(make_gait_policy(args.gait).gait_row)
    skill, axis = mode.split("_")
    cfg = load_config("ppo")
    try:
        sim = parse_sim_overrides(args.sim)  # a bad --sim fails here, before any simulation
    except ValueError as e:
        ap.error(str(e))
    if sim:
        cfg["env"]["task_config"] = dict(cfg["env"].get("task_config") or {}, sim=sim)
    if args.drift < 0:
        ap.error("--drift must be >= 0")
    if args.obs_std_min is not None:
        if args.obs_std_min < 0:
            ap.error("--obs-std-min must be >= 0")
        cfg["model"]["obs_std_min"] = args.obs_std_min
    if args.grasps is not None:
        cfg["env"]["grasp_dataset"] = grasp_dataset_file(args.grasps, "--grasps")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(args.seed)

    obs = None
    labels = None
    policy = actor = None
    log = []
    fitted = {}  # round -> the network that round rolled out (its state, its success rate)
    t0 = time.time()
    ctx = mp.get_context("spawn")

    def beta_of(r: int) -> float:  # the last round measures the network alone
        return 0.0 if r in (0, args.rounds) else args.beta ** r

    def collect(objects: str, limit: int, trials: int, seed: int, randomize: bool, student, beta: float,
                drift: float = 0.0) -> list:
        """Every worker's :func:`_rollouts` of one round (or of the held-out evaluation)."""
        with ProcessPoolExecutor(args.workers, mp_context=ctx) as ex:
            return [f.result() for f in [ex.submit(_rollouts, args.gait, args.hand, objects, limit, trials, seed,
                                                    randomize, student, (i, args.workers), beta, args.privileged_q0,
                                                    args.clock, args.history, args.sequence, mode, args.grasps,
                                                    args.progress, sim, drift)
                                          for i in range(args.workers)]]

    for r in range(args.rounds + 1):
        parts = collect(args.objects, args.limit, args.trials, args.seed + 7919 * r, args.randomize,
                        None if r == 0 else actor, beta_of(r), 0.0 if r == args.rounds else args.drift)
        o = {k: torch.cat([p[0][k] for p in parts]) for k in parts[0][0]}
        y = torch.cat([p[1] for p in parts])
        trials = [t for p in parts for t in p[2]]
        sr = sum(t["success"] for t in trials) / len(trials)
        drops = sum(t["dropped"] for t in trials) / len(trials) if "dropped" in trials[0] else float("nan")
        who = "gait" if r == 0 else ("network" if beta_of(r) == 0 else f"network, gait at {beta_of(r):.3g} of steps")
        row = dict(round=r, actor=who, episodes=len(trials), success=sr, dropped=drops, new_states=len(y),
                   wall_s=round(time.time() - t0, 1))
        if actor is not None:  # the network's error on states it was not fitted to (before it sees them)
            with torch.no_grad():
                loc, _ = actor(o["hand"], o["object"], o["goal"])
                err = (loc.clamp(-1, 1) - y).pow(2).mean(-1)
                stopped = (y == 0).all(-1)  # the gait's stop: the object has turned far enough
                row["fresh_mse"] = float(err.mean())
                row["fresh_mse_moving"] = float(err[~stopped].mean()) if (~stopped).any() else float("nan")
                row["fresh_mse_stopped"] = float(err[stopped].mean()) if stopped.any() else float("nan")
                row["stopped_share"] = float(stopped.float().mean())
        if r > 0 and beta_of(r) == 0:  # only rollouts of the network alone select it
            fitted[r]["success"] = sr
        if r == args.rounds:  # the last round only measures the final network
            log.append(row)
            print(json.dumps(row), flush=True)
            break
        obs = o if obs is None else {k: torch.cat([obs[k], o[k]]) for k in o}
        labels = y if labels is None else torch.cat([labels, y])
        if policy is None:
            dims = {k: v.shape[-1] for k, v in obs.items()}
            policy, _, norm = make_models(dims, y.shape[-1], None, cfg["model"])
            actor = policy.module[0].module
        with torch.no_grad():  # the statistics of all the data so far
            for k in dims:
                getattr(norm, f"{k}_mean").zero_()
                getattr(norm, f"{k}_var").fill_(1.0)
            norm.count.fill_(1e-4)
        norm.update(obs)
        opt = torch.optim.AdamW(actor.net.parameters(), lr=args.lr, weight_decay=args.weight_decay)
        n = len(labels)
        for _ in range(args.epochs):
            perm = torch.randperm(n)
            for i in range(0, n, args.batch):
                idx = perm[i:i + args.batch]
                loc, _ = actor(obs["hand"][idx], obs["object"][idx], obs["goal"][idx])
                loss = torch.nn.functional.mse_loss(loc, labels[idx])
                opt.zero_grad()
                loss.backward()
                opt.step()
        with torch.no_grad():
            loc, _ = actor(obs["hand"], obs["object"], obs["goal"])
            row["mse"] = float(torch.nn.functional.mse_loss(loc.clamp(-1, 1), labels))
            row["label_var"] = float(labels.var(0).mean())
            row["states"] = n
        fitted[r + 1] = dict(state={k: v.clone() for k, v in policy.state_dict().items()})
        log.append(row)
        print(json.dumps(row), flush=True)
        with open(out / "log.jsonl", "w") as f:
            f.writelines(json.dumps(x) + "\n" for x in log)

    best = max((k for k in fitted if "success" in fitted[k]), key=lambda k: (fitted[k]["success"], k))
    log.append(dict(kept_round=best, success=fitted[best]["success"]))
    ck = dict(policy=fitted[best]["state"], obs_dims=dims, n_act=labels.shape[-1], modes=list(F.MODES), config=cfg,
              skill=skill, axis=axis, hand=args.hand, env_id=R.skill(skill).env_id,
              env_kwargs=env_kwargs_for(skill, axis, args.hand, cfg["env"]), iteration=0,
              frames=sum(row.get("new_states", 0) for row in log),  # every control step simulated, all rounds
              git_commit=git_commit(), commits=[git_commit()],
              clone_of=args.gait or f"seq:{args.sequence}",
              wall_s=round(time.time() - t0, 1))
    diagnosis = args.privileged_q0 or args.clock or args.history or args.progress
    if not diagnosis:
        torch.save(ck, out / "policy.pt")
    with open(out / "log.jsonl", "w") as f:
        f.writelines(json.dumps(x) + "\n" for x in log)
    (out / "command.txt").write_text("python benchmarks/gait_clone.py " + " ".join(sys.argv[1:] if argv is None else argv)
                                     + f"  # commit {git_commit()}\n")
    if args.heldout:
        policy.load_state_dict(fitted[best]["state"])
        parts = collect(args.heldout_objects, args.heldout, 3, 0, False, actor, 0.0)
        trials = sorted((t for p in parts for t in p[2]), key=lambda t: (t.get("object", ""), t.get("trial", 0)))
        k, n = sum(bool(t["success"]) for t in trials), len(trials)
        lo, hi = wilson_interval(k, n)
        held = dict(objects=args.heldout_objects, limit=args.heldout, trials_per_object=3, seed=0, round=best,
                    success=k, n=n, rate=k / n, wilson95=[lo, hi],
                    dropped=sum(bool(t.get("dropped")) for t in trials), trials=trials)
        (out / "heldout.json").write_text(json.dumps(held, default=float) + "\n")
        print(f"held out ({args.heldout_objects}, first {args.heldout} per group x 3, seed 0): {k} of {n} "
              f"({100 * k / n:.1f}% [{100 * lo:.1f}-{100 * hi:.1f}]), {held['dropped']} dropped", flush=True)
    what = "(not written: a diagnosis run)" if diagnosis else f"wrote {out / 'policy.pt'}:"
    print(f"{what} the network of round {best} ({100 * fitted[best]['success']:.1f}% "
          f"of its episodes; {time.time() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
