"""Ship the selected gait of a --sample search as unicross/checkpoints/allegro/gaits/rotate_AXIS.json (rule.txt),
keeping the gait it replaces in `replaced`.

    python docs/runs/gait_search/sampled/ship.py AXIS LOG.jsonl.gz HELDOUT_FILE "COMMAND" "WHY"
"""
import json
import platform
import subprocess
import sys
from pathlib import Path

from unicross.gaits import best_gait
from unicross.evaluation import read_results

axis, log, heldout, command, why = sys.argv[1:6]
target = Path(f"unicross/checkpoints/allegro/gaits/rotate_{axis}.json")
old = json.loads(target.read_text())
_, row = best_gait(log)
res = read_results(heldout)
old_sr = old["evaluations"][0]["summaries"]["rotate"]["sr"]
new = dict(
    mode=f"rotate_{axis}", search_log=log, hand="allegro", kind=old["kind"], p=row["p"], meta=row["meta"],
    success=row["success"], score=row["score"], selection_episodes=len(row["r"]),
    commands=[command, f"selected row of {Path(log).name}: the highest selection success (unicross.gaits.best_gait)"],
    git_commit=subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip(),
    hardware=dict(machine=platform.machine(), cpus=2, python=platform.python_version()),
    evaluation_command=f"unicross eval --policy gait:{log} --protocol rotate --axis {axis} --objects test --limit 20 "
                       f"--trials-per-object 3 --seed 0 --workers 2 --out {heldout}",
    evaluations=[dict(file=heldout, objects=res["objects"], limit=res["limit"], trials_per_object=res["trials_per_object"],
                      seed=res["seed"], axes=res["axes"], summaries=res["summaries"])],
    replaced=dict(search_log=old["search_log"], p=old["p"], meta=old["meta"], success=old["success"],
                  heldout=old_sr, heldout_file=old["evaluations"][0]["file"], why=why,
                  **({"replaced": old["replaced"]} if "replaced" in old else {})),
)
target.write_text(json.dumps(new, indent=1) + "\n")
print(f"wrote {target}: held out {res['summaries']['rotate']['sr']:.1f}% (was {old_sr:.1f}%)")
