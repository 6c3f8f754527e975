"""Two evaluations of the same trials (same protocol, objects, trials per object and seed), compared trial by
trial: each one's success rate with its 95% Wilson interval, the trials only one of them solves, the
difference with its 95% interval (paired, Newcombe's method 10 from the two Wilson intervals and the
correlation of the pairs) and the exact McNemar p (two-sided binomial test on the discordant pairs).

    python docs/runs/paper_protocol/paired.py A.json[.gz] B.json[.gz] [--skill translate]

Either side may be several evaluations joined by commas (e.g. the same cell under evaluation seeds 1, 2 and 3,
``A1,A2,A3 B1,B2,B3``): their trials are pooled (a trial is keyed by object, axis, trial and seed).
"""
import argparse
import math

from unicross.evaluation import read_results
from unicross.metrics import wilson_interval as wilson


def mcnemar_exact(b, c):
    """Two-sided exact p of b against b + c discordant pairs under p = 1/2."""
    n = b + c
    if n == 0:
        return 1.0
    tail = sum(math.comb(n, i) for i in range(0, min(b, c) + 1)) / 2 ** n
    return min(1.0, 2 * tail)


def paired_cells(pairs):
    """(a, b, c, d) of an iterable of (first succeeded, second succeeded): a both, b only the first, c only the
    second, d neither."""
    cells = [0, 0, 0, 0]
    for x, y in pairs:
        x, y = bool(x), bool(y)
        cells[0 if x and y else 1 if x else 2 if y else 3] += 1
    return tuple(cells)


def newcombe_paired(a, b, c, d, z=1.96):
    """95% interval of p1 - p2 for paired proportions (Newcombe 1998, method 10): a both succeed, b only
    the first, c only the second, d neither."""
    n = a + b + c + d
    l1, u1 = wilson(a + b, n, z)
    l2, u2 = wilson(a + c, n, z)
    p1, p2 = (a + b) / n, (a + c) / n
    denom = math.sqrt((a + b) * (c + d) * (a + c) * (b + d))
    phi = 0.0 if denom == 0 else (a * d - b * c) / denom
    dl = math.sqrt((p1 - l1) ** 2 - 2 * phi * (p1 - l1) * (u2 - p2) + (u2 - p2) ** 2)
    du = math.sqrt((u1 - p1) ** 2 - 2 * phi * (u1 - p1) * (p2 - l2) + (p2 - l2) ** 2)
    return p1 - p2 - dl, p1 - p2 + du


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("first", help="an evaluation (results file or folder), or several joined by commas")
    p.add_argument("second", help="the same, of the other policy")
    p.add_argument("--skill", default=None, help="the protocol's key in 'trials' (default: the only one)")
    args = p.parse_args()
    runs = [[read_results(f) for f in side.split(",")] for side in (args.first, args.second)]
    skill = args.skill or next(iter(runs[0][0]["trials"]))
    key = ("object", "axis", "trial", "seed")
    trials = [{tuple(t[k] for k in key): t["success"] for r in side for t in r["trials"][skill]} for side in runs]
    if any(len(trials[i]) != sum(len(r["trials"][skill]) for r in runs[i]) for i in (0, 1)):
        raise SystemExit("the evaluations of one side repeat trials (the same seed twice?)")
    if trials[0].keys() != trials[1].keys():
        raise SystemExit("the two evaluations did not run the same trials")
    a, b, c, d = paired_cells((trials[0][k], trials[1][k]) for k in trials[0])
    n = a + b + c + d
    for side, k in zip(runs, (a + b, a + c)):
        lo, hi = wilson(k, n)
        print(f"{side[0]['label']:40s} {100 * k / n:5.1f}% [{100 * lo:.1f}-{100 * hi:.1f}] ({k} of {n})")
    lo, hi = newcombe_paired(a, b, c, d)
    print(f"difference (first - second): {100 * (b - c) / n:+.1f} points [{100 * lo:+.1f}, {100 * hi:+.1f}]; "
          f"only the first: {b}, only the second: {c}; exact McNemar p = {mcnemar_exact(b, c):.3g}")


if __name__ == "__main__":
    main()
