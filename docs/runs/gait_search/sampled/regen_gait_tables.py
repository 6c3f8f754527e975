"""Regenerate only the scripted-gait sections of docs/results.md after shipped gaits were replaced.

The report's other cells do not read the gaits (experts, student, baselines, long horizon), so their numbers stand;
this runs the report's own code for the two gait tables (`PaperReport._gait_tables`, with the parameters of the
command at the file's top), splices them in with a line saying when, where and why they were regenerated, and prints
the rows of the gaits that were not replaced beside the file's. Evaluations are deterministic for a seed and a policy
on one machine, not across CPUs (the physics' floating point differs, and over 400 steps a few trials' outcomes flip:
2026-11-28, y+ 42.0 in the full run against 39.0 here), so those rows are reported, not required to match.

    python docs/runs/gait_search/sampled/regen_gait_tables.py docs/results.md rotate_x+ [rotate_z- ...]
"""
import datetime
import re
import subprocess
import sys
from pathlib import Path

from unicross.report import PaperReport


def main():
    path, replaced = Path(sys.argv[1]), set(sys.argv[2:])
    text = path.read_text()
    command = re.search(r"^Command: `(.*)`$", text, re.M).group(1)
    want = {"--hand": "allegro", "--limit": "10", "--trials-per-object": "3", "--min-trials": "100", "--seed": "0"}
    args = command.split()
    for k, v in want.items():
        if k not in args or args[args.index(k) + 1] != v:
            sys.exit(f"{path}: its command {command!r} does not have {k} {v}, the parameters this script uses")
    report = PaperReport(hand="allegro", limit=10, trials=3, workers=2, seed=0, min_trials=100)
    new = report._gait_tables()
    lines = text.split("\n")
    start = lines.index("## Scripted finger gaits (not PPO experts), held-out test objects")
    end = next(i for i in range(start + 1, len(lines)) if lines[i].startswith("## ") and "Scripted finger gaits" not in lines[i])
    old = lines[start:end]
    row = re.compile(r"^\| (rotate_[xyz][+-]) \| gait:")
    old_rows = [ln for ln in old if row.match(ln)]
    new_rows = [ln for ln in new if row.match(ln)]
    assert len(old_rows) == len(new_rows), (old_rows, new_rows)
    moved = []
    for a, b in zip(old_rows, new_rows):
        mode = row.match(a).group(1)
        print(("replaced  " if mode in replaced else "unchanged ") + f"file: {a}\n{'':10}now:  {b}")
        if mode not in replaced and a != b:
            cell = [r.split(" | ")[2] for r in (a, b)]  # "SR [CI] (n), Rot. X rad"
            moved.append(f"{mode} {cell[0].split(' [')[0]}, Rot. {cell[0].split('Rot. ')[-1]} -> "
                         f"{cell[1].split(' [')[0]}, Rot. {cell[1].split('Rot. ')[-1]}")
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    note = (f"_These gait tables were regenerated on {datetime.date.today()} at {commit} (2 CPU cores) after the "
            f"{', '.join(sorted(replaced))} gait(s) were replaced, by `python docs/runs/gait_search/sampled/"
            f"regen_gait_tables.py {path} {' '.join(sorted(replaced))}` (the report's own code for these tables); the "
            f"other sections are from the full run of the command above. The gaits not replaced gave "
            + (f"other numbers here than in that run ({'; '.join(moved)}): outcomes differ between CPUs._"
               if moved else "their rows of that run unchanged._"))
    new = new[:2] + [note, ""] + new[2:]
    path.write_text("\n".join(lines[:start] + new + lines[end:]))
    print(f"wrote {path}")


if __name__ == "__main__":  # the evaluation's worker processes import this file
    main()
