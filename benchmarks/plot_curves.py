"""Learning curves of PPO runs as one PNG: held-out evaluation success (paper protocol, with its
95% Wilson interval) and training-episode return against frames, one line per run.

    python benchmarks/plot_curves.py runs/grasp_s0 runs/grasp_s1 runs/grasp_s2 --out docs/grasp_curves.png

Reads each run's ``metrics.jsonl`` (written by ``unicross train``). DAgger runs (``unicross
distill``) are drawn as the per-mode action MSE against the experts and the per-mode success of
the student's own training episodes:

    python benchmarks/plot_curves.py runs/student_s0 --out docs/student_curves.png

Clones of scripted behaviours (``benchmarks/gait_clone.py``, its ``log.jsonl``) are drawn as the success
of each DAgger round's rollouts (round 0: the teacher) with its 95% Wilson interval, and the network's
action error on each round's new states before it was fitted to them, against the states gathered:

    python benchmarks/plot_curves.py runs/clone_s0 runs/clone_s1 --out docs/clone_curves.png

Needs matplotlib (``pip install matplotlib``).
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path


def load(run: Path):
    rows = [json.loads(line) for line in (run / "metrics.jsonl").read_text().splitlines() if line.strip()]
    evals = [r for r in rows if "eval_success" in r]
    train = [r for r in rows if "episode_return" in r]
    return evals, train


def smooth(xs, k: int = 10):
    out, acc = [], []
    for x in xs:
        acc.append(x)
        acc = acc[-k:]
        out.append(sum(acc) / len(acc))
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("runs", nargs="+")
    p.add_argument("--out", required=True)
    p.add_argument("--title", default=None)
    args = p.parse_args(argv)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    runs = list(map(Path, args.runs))
    if all(is_clone(r) for r in runs):
        return plot_clone(runs, fig, a, b, args)
    if all(is_dagger(r) for r in runs):
        return plot_dagger(runs, fig, a, b, args)
    for run in runs:
        evals, train = load(run)
        if evals:
            f = [r["frames"] for r in evals]
            line, = a.plot(f, [100 * r["eval_success"] for r in evals], marker="o", ms=3,
                           label=f"{run.name} (n={evals[0]['eval_n']})")
            a.fill_between(f, [100 * r["eval_ci95_low"] for r in evals], [100 * r["eval_ci95_high"] for r in evals],
                           color=line.get_color(), alpha=0.12)
        if train:
            b.plot([r["frames"] for r in train], smooth([r["episode_return"] for r in train]), label=run.name)
    a.set(xlabel="frames", ylabel="success (%)", ylim=(-2, 102),
          title="held-out evaluation (paper protocol, 95% CI)")
    b.set(xlabel="frames", ylabel="episode return (raw, smoothed)", title="training episodes")
    for ax in (a, b):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    return save(fig, args)


def save(fig, args, rect=(0, 0, 1, 1)) -> int:
    """Writes the figure; ``rect``: the part of it the axes fill (room for a figure legend)."""
    if args.title:
        fig.suptitle(args.title)
    fig.tight_layout(rect=rect)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")
    return 0


def is_clone(run: Path) -> bool:
    return (run / "log.jsonl").exists() and not (run / "metrics.jsonl").exists()


def plot_clone(runs, fig, a, b, args) -> int:
    """Per run: the success of each round's rollouts (Wilson 95%) and the fresh action error."""
    from unicross.metrics import wilson_interval
    for run in runs:
        rows = [r for r in (json.loads(line) for line in (run / "log.jsonl").read_text().splitlines() if line.strip())
                if "round" in r]
        x = [sum(q["new_states"] for q in rows[:i + 1]) for i in range(len(rows))]
        k = [round(r["success"] * r["episodes"]) for r in rows]
        ci = [wilson_interval(kk, r["episodes"]) for kk, r in zip(k, rows)]
        line, = a.plot(x, [100 * r["success"] for r in rows], marker="o", ms=3,
                       label=f"{run.name} (n={rows[0]['episodes']} per round)")
        a.fill_between(x, [100 * lo for lo, _ in ci], [100 * hi for _, hi in ci], color=line.get_color(), alpha=0.12)
        pts = [(xx, r["fresh_mse"]) for xx, r in zip(x, rows) if "fresh_mse" in r]
        b.plot([p_[0] for p_ in pts], [p_[1] for p_ in pts], marker="o", ms=3, color=line.get_color(), label=run.name)
    a.set(xlabel="states gathered (control steps)", ylabel="success (%)", ylim=(-2, 102),
          title="rollouts per DAgger round (round 0: the teacher; 95% CI)")
    b.set(xlabel="states gathered (control steps)", ylabel="action MSE", yscale="log",
          title="network's error on each round's new states")
    for ax in (a, b):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    return save(fig, args)


def is_dagger(run: Path) -> bool:
    first = (run / "metrics.jsonl").read_text().split("\n", 1)[0]
    return '"buffer"' in first and '"epoch"' in first  # a warm-up epoch (optim.warmup_frames) logs no mse


def plot_dagger(runs, fig, a, b, args) -> int:
    """One colour per mode, one line style per run (seeds), and a legend of each."""
    from matplotlib.lines import Line2D
    styles = ["-", "--", ":", "-."]
    data = [[json.loads(line) for line in (run / "metrics.jsonl").read_text().splitlines() if line.strip()]
            for run in runs]
    modes = sorted({k.split("/", 1)[1] for rows in data for r in rows for k in r if k.startswith("mse/")})
    colour = {m: f"C{i % 10}" for i, m in enumerate(modes)}
    for j, rows in enumerate(data):
        ls = styles[j % len(styles)]
        for m in modes:
            pts = [(r["frames"], r[f"mse/{m}"]) for r in rows if f"mse/{m}" in r]
            a.plot([f for f, _ in pts], [v for _, v in pts], color=colour[m], ls=ls, lw=1)
            pts = [(r["frames"], 100 * r[f"success/{m}"]) for r in rows if f"success/{m}" in r]
            b.plot([f for f, _ in pts], smooth([v for _, v in pts], 25), color=colour[m], ls=ls, lw=1)
    a.set(xlabel="frames", ylabel="action MSE to the expert", yscale="log", title="distillation loss per mode")
    b.set(xlabel="frames", ylabel="success (%), smoothed", ylim=(-2, 102),
          title="student's training episodes (randomised, perturbed)")
    handles = [Line2D([], [], color=colour[m], label=m) for m in modes]
    if len(runs) > 1:
        handles += [Line2D([], [], color="k", ls=styles[j % len(styles)], label=run.name) for j, run in enumerate(runs)]
    for ax in (a, b):
        ax.grid(alpha=0.3)
    fig.legend(handles=handles, loc="center right", fontsize=8)
    return save(fig, args, rect=(0, 0, 0.83, 1))


if __name__ == "__main__":
    raise SystemExit(main())
