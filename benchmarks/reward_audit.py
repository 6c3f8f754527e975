"""Reward audit of every mode as a report: reference behaviours ranked by the return PPO sees
(discounted by gamma, times reward_scale), with our coefficients and with the paper's.

    python benchmarks/reward_audit.py --out docs/reward_audit.md [--limit 2 --seeds 3]

Grasp and relocate use the training objects (first ``limit`` per group); rotate and translate run
every axis/direction. See ``unicross/audit.py`` for the behaviours.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

from unicross.audit import ASCENT_FRACTIONS, ascent, audit, behaviours, first_dip, format_rows, physical_reference
from unicross.config import load_preset
from unicross.registry import SKILLS

MODES = [(s.name, a) for s in SKILLS.values() for a in (s.axes or (None,))]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default="docs/reward_audit.md")
    p.add_argument("--limit", type=int, default=2)
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--in-hand-seeds", type=int, default=1, help="episodes per object for rotate/translate (400/64 steps)")
    p.add_argument("--ascent-seeds", type=int, default=2, help="episodes per object on each ascent step")
    p.add_argument("--modes", default=None, help="comma list like grasp,rotate:x+ (default: all ten)")
    args = p.parse_args(argv)
    modes = MODES
    if args.modes:
        want = [m.split(":") for m in args.modes.split(",")]
        modes = [(m[0], m[1] if len(m) > 1 else None) for m in want]
    lines = ["# Reward audit", "",
             "Reference behaviours per mode, ranked by their return as PPO sees it (each term discounted by "
             "gamma and multiplied by reward_scale; `configs/ppo.yaml` training env). `raw return` is the "
             "undiscounted, unscaled sum. Made by `python benchmarks/reward_audit.py "
             f"--limit {args.limit} --seeds {args.seeds} --in-hand-seeds {args.in_hand_seeds} --ascent-seeds {args.ascent_seeds}`.", ""]
    verdict, ascents = [], []
    for skill, axis in modes:
        seeds = args.seeds if skill in ("grasp", "relocate") else args.in_hand_seeds
        limit = args.limit if skill in ("grasp", "relocate") else 1
        ref = next(iter(behaviours(skill)))
        for label, preset in (("ours", None), ("paper", "paper_reward")):
            t0 = time.time()
            rows = audit(skill, axis, limit=limit, seeds=seeds, progress=False,
                         ppo_overrides=load_preset(preset) if preset else None)
            rank = 1 + [r.behaviour for r in rows].index(ref)
            title = f"{skill}{' ' + axis if axis else ''}"
            lines += [f"## {title}: {label} coefficients (reference `{ref}` ranks {rank}/{len(rows)}; "
                      f"{time.time() - t0:.0f} s)", "", format_rows(rows), ""]
            names = [r.behaviour for r in rows]
            phys = physical_reference(skill, axis)
            shown = phys or ("gait" if "gait" in names else None)  # rotate: the shipped scripted gait
            phys_cell = f"`{shown}` {1 + names.index(shown)} (zero {1 + names.index('zero')})" if shown in names else "--"
            verdict.append(f"| {title} | {label} | {rank} of {len(rows)} | {phys_cell} | {rows[0].behaviour} |")
            print(f"{title} ({label}): reference {ref} ranks {rank}/{len(rows)}", flush=True)
            if phys:
                t0 = time.time()
                path = ascent(skill, axis, limit=args.limit, seeds=args.ascent_seeds, progress=False,
                              ppo_overrides=load_preset(preset) if preset else None)
                dip = first_dip(path)
                lines += [f"### {title}: {label} coefficients, ascent to `{phys}` (its rate scaled from 0; "
                          f"{'rises all the way' if dip is None else 'first falls at ' + dip}; "
                          f"{time.time() - t0:.0f} s)", "", format_rows(path).replace("| rank |", "| step |"), ""]
                ascents.append(f"| {title} | {label} | " + " | ".join(f"{r.total:.2f}" for r in path)
                               + f" | {dip or 'none'} |")
    summary = ["## Summary", "",
               "The successful reference is the first behaviour of each mode (in-hand: the kinematic oracle). "
               "A physical reference (`unicross.audit.physical_reference`) does the mode through the physics "
               "alone; it must out-earn the zero action. Rotate has none that keeps turning; the shipped scripted "
               "gait (`gait`: turns past the success angle, then holds; `unicross.gaits`) stands in for it.", "",
               "| mode | coefficients | rank of the successful reference | physical reference rank (zero's) | first |",
               "|---|---|---|---|---|"] + verdict + [""]
    if ascents:
        summary += ["PPO starts at the zero action and climbs the return's gradient: the return must rise along the "
                    "path to the physical reference, not only at its end (`unicross.audit.ascent`: the reference at "
                    f"fractions {', '.join(f'{f:g}' for f in ASCENT_FRACTIONS)} of its rate).", "",
                    "| mode | coefficients | " + " | ".join(f"x{f:g}" for f in ASCENT_FRACTIONS) + " | first dip |",
                    "|---|---|" + "---|" * (len(ASCENT_FRACTIONS) + 1)] + ascents + [""]
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text("\n".join(lines[:4] + summary + lines[4:]) + "\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
