"""Ship the selected gait of a --sample search as unicross/checkpoints/HAND/gaits/rotate_AXIS.json (rule.txt; HAND
default allegro), keeping a gait it replaces in `replaced`.

    python docs/runs/gait_search/sampled/ship.py AXIS LOG.jsonl.gz HELDOUT_FILE "COMMAND" "WHY" [HAND]
"""
import json
import platform
import subprocess
import sys
from pathlib import Path

from unicross.gaits import best_gait
from unicross.evaluation import read_results

axis, log, heldout, command, why = sys.argv[1:6]
hand = sys.argv[6] if len(sys.argv) > 6 else "allegro"
target = Path(f"unicross/checkpoints/{hand}/gaits/rotate_{axis}.json")
old = json.loads(target.read_text()) if target.exists() else None
_, row = best_gait(log)
assert row["meta"].get("hand", "allegro") == hand, (row["meta"].get("hand"), hand)
res = read_results(heldout)
new = dict(
    mode=f"rotate_{axis}", search_log=log, hand=hand, kind="scripted finger gait (unicross.gaits), not a PPO expert",
    p=row["p"], meta=row["meta"],
    success=row["success"], score=row["score"], selection_episodes=len(row["r"]),
    commands=[command, f"selected row of {Path(log).name}: the highest selection success (unicross.gaits.best_gait)"],
    git_commit=subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip(),
    hardware=dict(machine=platform.machine(), cpus=2, python=platform.python_version()),
    evaluation_command=f"unicross eval --policy gait:{log} --hand {hand} --protocol rotate --axis {axis} --objects test "
                       f"--limit 20 --trials-per-object 3 --seed 0 --workers 2 --out {heldout}",
    evaluations=[dict(file=heldout, objects=res["objects"], limit=res["limit"], trials_per_object=res["trials_per_object"],
                      seed=res["seed"], axes=res["axes"], summaries=res["summaries"])],
    why=why,
)
if old is not None:
    old_sr = old["evaluations"][0]["summaries"]["rotate"]["sr"]
    new["replaced"] = dict(search_log=old["search_log"], p=old["p"], meta=old["meta"], success=old["success"],
                           heldout=old_sr, heldout_file=old["evaluations"][0]["file"], why=why,
                           **({"replaced": old["replaced"]} if "replaced" in old else {}))
    del new["why"]
target.parent.mkdir(parents=True, exist_ok=True)
target.write_text(json.dumps(new, indent=1) + "\n")
print(f"wrote {target}: held out {res['summaries']['rotate']['sr']:.1f}%"
      + (f" (was {new['replaced']['heldout']:.1f}%)" if old is not None else ""))
