"""The shipped rotate clones (or, with ``--gaits``, the shipped scripted gaits) on their 120-trial held-out
cells, under 8 iterations (their evaluations when shipped, named in each sidecar) against 12 (runs of
`unicross eval ... --sim solver_position_iterations=12` in DIR, files ``shipped_AXIS.json[.gz]`` or
``gait_AXIS.json[.gz]``), paired trial by trial (the same objects, starts and seeds):

    python docs/runs/physics_settings/paired_shipped.py docs/runs/physics_settings/shipped_it12
    python docs/runs/physics_settings/paired_shipped.py docs/runs/physics_settings/gaits_it12 --gaits
"""
import gzip
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "docs/runs/paper_protocol"))
from paired import mcnemar_exact, newcombe_paired, paired_cells  # noqa: E402

AT8 = {"x+": "docs/runs/gait_clone/rotate_x+_beta_floor1e-2/heldout",
       "x-": "docs/runs/gait_clone/rotate_x-_beta_floor1e-2/heldout",
       "y+": "docs/runs/gait_clone/rotate_y+_reversed_beta_floor1e-2/heldout",
       "y-": "docs/runs/nostop/clone_y-_shipped/eval_test120",
       "z+": "docs/runs/nostop/clone_z+_shipped/eval_test120",
       "z-": "docs/runs/nostop/clone_z-_shipped/eval_test120"}
GAITS_AT8 = {"x+": "docs/runs/gait_search/heldout/rotate_x+_sampled",
             "x-": "docs/runs/gait_search/heldout/rotate_x-_sampled",
             "y+": "docs/runs/gait_search/heldout/rotate_y+",
             "y-": "docs/runs/gait_search/heldout/rotate_y-_phase",
             "z+": "docs/runs/gait_search/heldout/rotate_z+",
             "z-": "docs/runs/gait_search/heldout/rotate_z-"}


def trials(path):
    raw = Path(path).read_bytes()
    r = json.loads(gzip.decompress(raw) if str(path).endswith(".gz") else raw)
    return {(t["object"], t["axis"], t["trial"]): t for t in r["trials"]["rotate"]}


def main():
    d12 = Path(sys.argv[1])
    gaits = "--gaits" in sys.argv[2:]
    at8, prefix = (GAITS_AT8, "gait") if gaits else (AT8, "shipped")
    pairs_all = []
    print("| axis | 8 iterations | 12 iterations | dropped (8 / 12) | paired difference [95% CI] | McNemar p |")
    print("|---|---|---|---|---|---|")
    for axis, f8 in at8.items():
        a, b = trials(ROOT / f8), trials(next(d12.glob(f"{prefix}_{axis}.json*")))
        assert a.keys() == b.keys(), axis
        pairs = [(b[k]["success"], a[k]["success"]) for k in a]
        pairs_all += pairs
        cells = paired_cells(pairs)
        lo, hi = newcombe_paired(*cells)
        k8, k12 = sum(t["success"] for t in a.values()), sum(t["success"] for t in b.values())
        d8, d12_ = sum(t["dropped"] for t in a.values()), sum(t["dropped"] for t in b.values())
        print(f"| {axis} | {k8} / {len(a)} | {k12} / {len(b)} | {d8} / {d12_} | {100 * (k12 - k8) / len(a):+.1f} "
              f"[{100 * lo:+.1f}, {100 * hi:+.1f}] | {mcnemar_exact(cells[1], cells[2]):.2g} |")
    cells = paired_cells(pairs_all)
    lo, hi = newcombe_paired(*cells)
    k12, k8 = sum(p[0] for p in pairs_all), sum(p[1] for p in pairs_all)
    print(f"| pooled | {k8} / {len(pairs_all)} | {k12} / {len(pairs_all)} | | {100 * (k12 - k8) / len(pairs_all):+.1f} "
          f"[{100 * lo:+.1f}, {100 * hi:+.1f}] | {mcnemar_exact(cells[1], cells[2]):.2g} |")


if __name__ == "__main__":
    main()
