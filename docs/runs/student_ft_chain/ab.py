"""The A/B of the chain-aware starts: seeds of two stages, each evaluated by ``seed_cells.py``, pooled.

    python docs/runs/student_ft_chain/ab.py A_CELLS.json [A_CELLS.json ...] -- B_CELLS.json [B_CELLS.json ...]

Prints, per group and pooled over its seeds: the ten modes' test successes, the rotate and translate cells, the long
horizon's overall successes (Gr.+Re.+Rot., Gr.+Re.+Trans.) and its in-hand phase per translate direction, each pooled
cell with its Wilson 95% interval, and B - A for the pooled rates with a Wald 95% interval of the difference
(the one docs/runs/student_ft_1202b/README.md uses).
"""
import json
import math
import sys

from unicross.metrics import wilson_interval


def rows(path):
    c = json.load(open(path))
    out = {m: (v["summary"]["successes"], v["summary"]["n"]) for m, v in c["test"].items()}
    out["ten modes"] = (sum(s for s, _ in out.values()), sum(n for _, n in out.values()))
    rot = [m for m in c["test"] if m.startswith("rotate")]
    out["rotate pooled"] = (sum(out[m][0] for m in rot), sum(out[m][1] for m in rot))
    for kind, s in c["long_horizon"]["summary"].items():
        out[kind] = (s["overall"]["successes"], s["overall"]["n"])
    for m, s in c["long_horizon"]["in_hand_phase_by_mode"].items():
        if m.startswith("translate"):
            out[f"chain in-hand {m}"] = (s["successes"], s["n"])
    return out


def pool(paths):
    per = [rows(p) for p in paths]
    return per, {k: (sum(r[k][0] for r in per), sum(r[k][1] for r in per)) for k in per[0]}


def cell(s, n):
    lo, hi = wilson_interval(s, n)
    return f"{100 * s / n:.1f} [{100 * lo:.1f}-{100 * hi:.1f}] ({s}/{n})"


if __name__ == "__main__":
    args = sys.argv[1:]
    if "--" not in args:
        raise SystemExit(__doc__)
    cut = args.index("--")
    (pa, a), (pb, b) = pool(args[:cut]), pool(args[cut + 1:])
    keys = [k for k in a if k in b]
    print("| cell | A seeds | A pooled | B seeds | B pooled | B - A [95%] |")
    print("|---|---|---|---|---|---|")
    for k in keys:
        (sa, na), (sb, nb) = a[k], b[k]
        p1, p2 = sa / na, sb / nb
        d, se = p2 - p1, math.sqrt(p1 * (1 - p1) / na + p2 * (1 - p2) / nb)
        print(f"| {k} | {' / '.join(str(r[k][0]) for r in pa)} | {cell(sa, na)} | "
              f"{' / '.join(str(r[k][0]) for r in pb)} | {cell(sb, nb)} | "
              f"{100 * d:+.1f} [{100 * (d - 1.96 * se):+.1f}, {100 * (d + 1.96 * se):+.1f}] |")
