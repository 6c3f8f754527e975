"""Judge a chain-aware clone's rule (this folder's rule.txt, ../rotate_zp_chain/rule.txt) against the shipped expert.

    python docs/runs/translate_zm_chain/judge.py [RUNS]    # translate z-; RUNS: runs/zmchain, or this folder's data/
    python docs/runs/translate_zm_chain/judge.py RUNS --mode rotate_z+ --gain 5    # ../rotate_zp_chain/
    python docs/runs/translate_zm_chain/judge.py RUNS --mode translate_z+ --gain 3 --guard    # ../translate_zp_chain/

(a) the chains of the ten experts (RUNS/chain_{shipped,cand}_sS.json) whose in-hand phase is of the mode's skill,
overall success, candidate against shipped, pooled over evaluation seeds 0-3 (--seeds) and paired by (seed, object, trial):
the gain must be >= GAIN points with the paired 95% interval above 0.
(b) the report's test cell of the mode (RUNS/cell_{shipped,cand}_sS.json) over the same four seeds: candidate >=
shipped - 3 points.
(c) with --guard: the same cell on unseen objects and with --disturb (RUNS/{unseen,dist}_{shipped,cand}_sS.json): in
neither is the candidate more than 5 points under the shipped expert with the paired 95% interval below 0.
Also prints each in-hand mode's phase after a successful relocation, as diagnosis.
"""
import gzip
import argparse
import json
import math
import sys
from pathlib import Path

ap = argparse.ArgumentParser()
ap.add_argument("runs", nargs="?", default="runs/zmchain")
ap.add_argument("--mode", default="translate_z-", help="the candidate's mode")
ap.add_argument("--gain", type=float, default=3.0, help="bar (a): the least chain gain, points")
ap.add_argument("--guard", action="store_true", help="bar (c): the unseen and --disturb cells")
ap.add_argument("--cand", default="cand", help="the candidate's file tag (RUNS/chain_TAG_sS.json, ...), e.g. cand1 "
                "for another training seed")
ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3], help="evaluation seeds (default 0-3)")
ARGS = ap.parse_args()
RUNS = Path(ARGS.runs)
SKILL = ARGS.mode.split("_")[0]
SEEDS = tuple(ARGS.seeds)


def load(name: str) -> dict:
    """RUNS/name, or its gzipped copy RUNS/name.gz (as committed)."""
    p = RUNS / name
    return json.loads(p.read_text() if p.exists() else gzip.decompress((RUNS / (name + ".gz")).read_bytes()))


def wilson(k: int, n: int, z: float = 1.96):
    if n == 0:
        return float("nan"), float("nan")
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return 100 * (c - h), 100 * (c + h)


def paired(a, b, z: float = 1.96):
    """Mean difference b - a of paired 0/1 outcomes (points) and its Wald 95% interval."""
    n = len(a)
    d = [float(y) - float(x) for x, y in zip(a, b)]
    m = sum(d) / n
    var = sum((x - m) ** 2 for x in d) / (n - 1)
    h = z * math.sqrt(var / n)
    return 100 * m, 100 * (m - h), 100 * (m + h)


def chains(who: str):
    out = {}
    for s in SEEDS:
        for t in load(f"chain_{who}_s{s}.json")["trials"]:
            if t["sequence"][-1].startswith(SKILL):
                out[(s, t["object"], t["trial"])] = t
    return out


def cell(who: str, setting: str = "cell"):
    out = {}
    for s in SEEDS:
        d = load(f"{setting}_{who}_s{s}.json")
        for t in d["trials"][SKILL]:
            out[(s, t["object"], t["trial"])] = bool(t["success"])
    return out


def line(name, k, n):
    lo, hi = wilson(k, n)
    return f"{name}: {k}/{n} = {100 * k / n:.1f}% [{lo:.1f}-{hi:.1f}]"


def main() -> int:
    sh, ca = chains("shipped"), chains(ARGS.cand)
    keys = sorted(sh)
    assert keys == sorted(ca), "the two sides' chains are not the same trials"
    for k in keys:  # same object, same random direction per trial
        assert sh[k]["sequence"] == ca[k]["sequence"], k
    a = [sh[k]["overall"] for k in keys]
    b = [ca[k]["overall"] for k in keys]
    print(f"(a) chains ending in {SKILL}, overall, evaluation seeds {SEEDS} (n = {len(keys)} chains)")
    print("    " + line("shipped", sum(a), len(a)))
    print("    " + line("candidate", sum(b), len(b)))
    diff, lo, hi = paired(a, b)
    disc = (sum(1 for x, y in zip(a, b) if y and not x), sum(1 for x, y in zip(a, b) if x and not y))
    print(f"    paired difference {diff:+.1f} [{lo:+.1f}, {hi:+.1f}] points (candidate-only / shipped-only successes {disc})")
    ok_a = diff >= ARGS.gain and lo > 0
    print(f"    bar: >= +{ARGS.gain:g} with the interval above 0: {'MET' if ok_a else 'NOT MET'}")
    for mode in sorted({sh[k]["sequence"][-1] for k in keys}):
        for who, d in (("shipped", sh), ("candidate", ca)):
            ph = [d[k] for k in keys if d[k]["sequence"][-1] == mode and d[k]["phase_success"][1]]
            ok = sum(1 for t in ph if t["phase_success"][2])
            drops = sum(1 for t in ph if not t["phase_success"][2] and t["dropped_in_phase"] == 2)
            print(f"    in-hand {mode} after relocation, {who}: {line('', ok, len(ph))[2:]}; failed by a drop {drops}")
    cs, cc = cell("shipped"), cell(ARGS.cand)
    ck = sorted(cs)
    assert ck == sorted(cc), "the two sides' cells are not the same trials"
    ks, kc = sum(cs[k] for k in ck), sum(cc[k] for k in ck)
    print(f"(b) {ARGS.mode} test cell, evaluation seeds {SEEDS} (n = {len(ck)})")
    print("    " + line("shipped", ks, len(ck)))
    print("    " + line("candidate", kc, len(ck)))
    d2, lo2, hi2 = paired([cs[k] for k in ck], [cc[k] for k in ck])
    print(f"    paired difference {d2:+.1f} [{lo2:+.1f}, {hi2:+.1f}] points")
    ok_b = 100 * kc / len(ck) >= 100 * ks / len(ck) - 3
    print(f"    bar: candidate >= shipped - 3: {'MET' if ok_b else 'NOT MET'}")
    ok_c = True
    if ARGS.guard:
        for setting, name in (("unseen", "unseen objects"), ("dist", "test objects, --disturb")):
            gs, gc = cell("shipped", setting), cell(ARGS.cand, setting)
            gk = sorted(gs)
            assert gk == sorted(gc), f"the two sides' {setting} cells are not the same trials"
            a3, b3 = [gs[k] for k in gk], [gc[k] for k in gk]
            d3, lo3, hi3 = paired(a3, b3)
            bad = 100 * (sum(b3) - sum(a3)) / len(gk) < -5 and hi3 < 0
            ok_c &= not bad
            print(f"(c) {ARGS.mode}, {name} (n = {len(gk)}): shipped {100 * sum(a3) / len(gk):.1f}%, candidate "
                  f"{100 * sum(b3) / len(gk):.1f}%, paired {d3:+.1f} [{lo3:+.1f}, {hi3:+.1f}]: "
                  f"{'NOT MET (over 5 points under, interval below 0)' if bad else 'MET'}")
    verdict = ok_a and ok_b and ok_c
    print("SHIP" if verdict else "NOT SHIPPED")
    return 0


if __name__ == "__main__":
    sys.exit(main())
