"""Regenerate only the scripted-gait sections of docs/results.md after shipped gaits were replaced.

The report's other cells do not read the gaits (experts, student, baselines, long horizon), so their numbers stand;
this runs the report's own code for the two gait tables (`PaperReport._gait_tables`, with the parameters of the
command at the file's top), splices them in with a line saying when, where and why they were regenerated, and prints
the rows of the gaits that were not replaced beside the file's. Evaluations are deterministic for a seed and a policy
on one machine, not across CPUs (the physics' floating point differs, and over 400 steps a few trials' outcomes flip:
2026-11-28, y+ 42.0 in the full run against 39.0 here), so those rows are reported, not required to match.

    python docs/runs/gait_search/sampled/regen_gait_tables.py docs/results.md rotate_x+ [rotate_z- ...]

The report's parameters (hand, objects per group, trials, seed) are read from the command at the file's top; a hand
whose report has no gait tables yet gets them where the report puts them (MODES: the gaits shipped, e.g.
`docs/results_sharpa_wave.md rotate_y+`).
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
    args = command.split()

    def arg(key, default):
        return args[args.index(key) + 1] if key in args else default
    report = PaperReport(hand=arg("--hand", "allegro"), limit=int(arg("--limit", 10)) or None,
                         trials=int(arg("--trials-per-object", 3)), workers=2, seed=int(arg("--seed", 0)),
                         min_trials=int(arg("--min-trials", 100)))
    new = report._gait_tables()
    lines = text.split("\n")
    first = "## Scripted finger gaits (not PPO experts), held-out test objects"
    if first in lines:  # the file's gait sections are replaced
        start = lines.index(first)
        end = next(i for i in range(start + 1, len(lines))
                   if lines[i].startswith("## ") and "Scripted finger gaits" not in lines[i])
    else:  # the hand's first gaits: where the report puts them, before the physical references or the baselines
        start = end = next(i for i, ln in enumerate(lines)
                           if ln.startswith(("## Physical references", "## Baselines")))
    row = re.compile(r"^\| (rotate_[xyz][+-]) \| gait:")

    def rows(block):  # (section index, mode) -> row
        out, section = {}, -1
        for ln in block:
            section += ln.startswith("## ")
            if row.match(ln):
                out[(section, row.match(ln).group(1))] = ln
        return out
    old_rows, new_rows = rows(lines[start:end]), rows(new)
    moved = []
    for key, b in new_rows.items():
        a = old_rows.get(key)
        mode = key[1]
        print(("replaced  " if mode in replaced else "unchanged " if a else "new       ") + f"file: {a}\n{'':10}now:  {b}")
        if mode not in replaced and a is not None and a != b:
            cell = [r.split(" | ")[2] for r in (a, b)]  # "SR [CI] (n), Rot. X rad"
            moved.append(f"{mode} {cell[0].split(' [')[0]}, Rot. {cell[0].split('Rot. ')[-1]} -> "
                         f"{cell[1].split(' [')[0]}, Rot. {cell[1].split('Rot. ')[-1]}")
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    kept = [key for key in new_rows if key in old_rows and key[1] not in replaced]
    note = (f"_These gait tables were regenerated on {datetime.date.today()} at {commit} (2 CPU cores) after the "
            f"{', '.join(sorted(replaced))} gait(s) were shipped, by `python docs/runs/gait_search/sampled/"
            f"regen_gait_tables.py {path} {' '.join(sorted(replaced))}` (the report's own code for these tables); the "
            f"other sections are from the full run of the command above."
            + ("" if not kept else " The gaits not replaced gave " + (
                f"other numbers here than the rows this file had ({'; '.join(moved)}): outcomes differ between CPUs."
                if moved else "the rows this file had, to the trial.")) + "_")
    new = new[:2] + [note, ""] + new[2:]
    out = lines[:start] + new + lines[end:]
    for mode in replaced:  # the expert tables point to the gait of a mode that has no expert, as the report does
        out = [ln.replace(f"| {mode} | expert not shipped |", f"| {mode} | expert not shipped (a scripted gait: see below) |")
               for ln in out]
    path.write_text("\n".join(out))
    print(f"wrote {path}")


if __name__ == "__main__":  # the evaluation's worker processes import this file
    main()
