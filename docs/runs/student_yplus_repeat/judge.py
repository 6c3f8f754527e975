"""rule.txt's clauses over the cells of the stage's seeds (seed_cells.py output), against the shipped stage's three.

    python docs/runs/student_yplus_repeat/judge.py docs/runs/student_yplus_repeat/cells_seed{0,1,2}.json

With one file: step 2's gate (seed 0 alone); with three: step 3 (the pooled seeds).
"""
import json
import sys

SHIPPED = [f"docs/runs/student_chain_starts/cells_share015_seed{s}.json" for s in range(3)]
CHAINS = ("Gr. + Re. + Rot.", "Gr. + Re. + Trans.")


def counts(path):
    d = json.load(open(path))
    out = {m: (c["summary"]["successes"], c["summary"]["n"]) for m, c in d["test"].items()}
    out.update({k: (v["overall"]["successes"], v["overall"]["n"]) for k, v in d["long_horizon"]["summary"].items()
                if k in CHAINS})
    return out


def pooled(paths):
    per = [counts(p) for p in paths]
    return {k: (100.0 * sum(c[k][0] for c in per) / sum(c[k][1] for c in per), "/".join(str(c[k][0]) for c in per))
            for k in per[0]}


def main():
    new, old = pooled(sys.argv[1:]), pooled(SHIPPED)
    gate = len(sys.argv) == 2
    slack = 8.0 if gate else 5.0
    ok = True
    print(f"{'cell':22s} {'this recipe':>20s} {'shipped stage':>20s}  bar")
    for k in new:
        if k == "translate_z-":
            bar = 79.0
        elif gate and k == "rotate_y+":
            bar = 44.0
        else:
            bar = old[k][0] - slack
        passed = new[k][0] >= bar - 1e-9
        ok &= passed
        print(f"{k:22s} {new[k][0]:6.1f} ({new[k][1]:>11s}) {old[k][0]:6.1f} ({old[k][1]:>11s})  >= {bar:5.1f} "
              f"{'ok' if passed else 'MISSED'}")
    step = "step 2 (gate to seeds 1 and 2)" if gate else "step 3 (ship seed 0)"
    print(f"{step}: {'PASSED' if ok else 'FAILED'}")


if __name__ == "__main__":
    main()
