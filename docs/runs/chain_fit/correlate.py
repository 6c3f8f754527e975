"""Which fitting error tracks the students' long-horizon Gr. + Re. + Trans. cell? (diagnosis, 66th session)

Per student export of docs/runs/student_l1 probed by probe.py: its Gr. + Re. + Trans. successes on the report's
trials (evaluation seed 0, n = 100; its student_cells_*.json) and the chained translate z+ / z- phases, against its
action error to the teachers per phase on the experts' translate chains (probe_test.json: the report's test trials;
probe_train.json: the same protocol on training objects) and its training log's grasp MSE (the mean of the last 100
epochs of metrics_*.jsonl, where kept). Spearman rank correlations (ties by order).

    python docs/runs/chain_fit/correlate.py > docs/runs/chain_fit/correlate.txt
"""
import json
import os
import statistics

HERE = os.path.dirname(os.path.abspath(__file__))
L1 = os.path.join(HERE, "..", "student_l1")


def ranks(xs):
    order = sorted(range(len(xs)), key=lambda i: xs[i])
    r = [0] * len(xs)
    for j, i in enumerate(order):
        r[i] = j
    return r


def spearman(a, b):
    return statistics.correlation(ranks(a), ranks(b))


if __name__ == "__main__":
    test = json.load(open(os.path.join(HERE, "probe_test.json")))["students"]
    train = json.load(open(os.path.join(HERE, "probe_train.json")))["students"]
    rows = []
    for path in test:
        if path not in train:
            continue
        tag = os.path.basename(path)[len("student_l1_"):-len(".pt")]
        lh = json.load(open(os.path.join(L1, f"student_cells_{tag}.json")))["long_horizon"]
        ih = lh["in_hand_phase_by_mode"]
        log = os.path.join(L1, f"metrics_{tag}.jsonl")
        mse = None
        if os.path.exists(log):
            tail = [json.loads(line) for line in open(log)][-100:]
            mse = statistics.mean(r["mse/grasp"] for r in tail)
        rows.append(dict(tag=tag, chain=lh["summary"]["Gr. + Re. + Trans."]["overall"]["successes"],
                         zp=ih["translate_z+"]["successes"], zm=ih["translate_z-"]["successes"], mse=mse,
                         test=test[path], train=train[path]))
    print(f"{len(rows)} students; Spearman rank correlation with Gr. + Re. + Trans. (overall / chained z+ phase / "
          f"chained z- phase), and the train probe's with the test probe's")
    for mode in ("grasp", "relocate", "translate_z+", "translate_z-"):
        for part in ("wrist", "fingers"):
            for where in ("test", "train"):
                x = [r[where][mode][part] for r in rows]
                line = (f"{where:5s} probe {mode:12s} {part:7s}: {spearman(x, [r['chain'] for r in rows]):+.2f} / "
                        f"{spearman(x, [r['zp'] for r in rows]):+.2f} / {spearman(x, [r['zm'] for r in rows]):+.2f}")
                if where == "train":
                    line += f"   train ~ test {spearman(x, [r['test'][mode][part] for r in rows]):+.2f}"
                print(line)
    logged = [r for r in rows if r["mse"] is not None]
    print(f"training log mse/grasp (last 100 epochs; {len(logged)} students with logs): "
          f"{spearman([r['mse'] for r in logged], [r['chain'] for r in logged]):+.2f} with the chain, "
          f"{spearman([r['mse'] for r in logged], [r['train']['grasp']['fingers'] for r in logged]):+.2f} with the "
          f"train probe's grasp fingers")
    print()
    print("| student | Gr.+Re.+Trans. (of 100) | z+ phase (of 55) | z- phase (of 45) | grasp wrist / fingers, train probe "
          "| relocate fingers, train probe | log mse/grasp |")
    print("|---|---|---|---|---|---|---|")
    for r in sorted(rows, key=lambda r: r["chain"]):
        g, rl = r["train"]["grasp"], r["train"]["relocate"]
        mse = f"{r['mse']:.2e}" if r["mse"] is not None else "--"
        print(f"| {r['tag']} | {r['chain']} | {r['zp']} | {r['zm']} | {g['wrist']:.2e} / {g['fingers']:.2e} | "
              f"{rl['fingers']:.2e} | {mse} |")
