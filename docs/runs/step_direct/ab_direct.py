"""In one process: full task steps/s with the compiled step math called directly (Inductor's graph,
``unicross.compiling._direct``, the default since the seventeenth session) against the same graphs
through AOTAutograd's runtime wrappers (what ``compile_fx`` returns), alternating the two 12 times on the
same held state (``benchmarks/env_throughput.py``'s loop: small random wrist actions, fingers holding).

    python docs/runs/step_direct/ab_direct.py [TASK ...] [--json out.json]
"""
import argparse
import json
import os
import statistics
import sys
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "benchmarks"))
os.environ["UNICROSS_COMPILE"] = "1"
import unicross.compiling as compiling  # noqa: E402

WRAPPED = {}  # id(direct callable) -> the wrapped callable it replaced
_direct = compiling._direct


def _recording(wrapped, inner, lifted, example):
    fn = _direct(wrapped, inner, lifted, example)
    WRAPPED[id(fn)] = wrapped
    return fn


compiling._direct = _recording
import env_throughput as et  # noqa: E402

TASKS = ["UniCross-Grasp-v1", "UniCross-Relocate-v1", "UniCross-Rotate-v1", "UniCross-Translate-v1",
         "UniCross-MultiSkill-v1"]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("tasks", nargs="*", default=TASKS)
    p.add_argument("--pairs", type=int, default=12)
    p.add_argument("--steps", type=int, default=300)
    p.add_argument("--json", default=None)
    args = p.parse_args()
    torch.set_num_threads(1)
    gs, objects = et.held_objects()
    rows = []
    for task in args.tasks:
        kw = dict(et.TASKS)[task]
        env, u = et._holding_env(task, kw, gs, objects)
        et._time_env(u, 5)
        state = u.get_state_dict()
        graphs = [g for gm in (u._step_math, u._command_math) for gl in gm._graphs.values() for g in gl]
        direct = [g.compiled for g in graphs]
        assert all(f.__name__ == "direct" for f in direct), "a graph runs wrapped: nothing to compare"
        ways = {"direct": direct, "wrapped": [WRAPPED[id(f)] for f in direct]}
        rates = {k: [] for k in ways}
        for _ in range(args.pairs):
            for name, fns in ways.items():
                for g, f in zip(graphs, fns):
                    g.compiled = f
                u.set_state_dict(state)
                rates[name].append(et._time_env(u, args.steps)[0])
        d, w = statistics.median(rates["direct"]), statistics.median(rates["wrapped"])
        row = dict(task=task, direct_steps_per_s=round(d, 1), wrapped_steps_per_s=round(w, 1),
                   ratio=round(d / w, 3), direct_faster_pairs=sum(a > b for a, b in zip(rates["direct"],
                                                                                       rates["wrapped"])),
                   pairs=args.pairs, runs={k: [round(r, 1) for r in v] for k, v in rates.items()})
        rows.append(row)
        print(json.dumps({k: v for k, v in row.items() if k != "runs"}), flush=True)
        env.close()
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
