"""Ship the clone of the width-switched teacher as allegro/translate_z- (rule.txt step 5): copy its policy and rewrite
the sidecar, the replaced record kept under ``replaced`` (its own ``replaced`` nested inside it).

    python docs/runs/translate_zm_reference/thickness/ship.py runs/clone_zm_thick_s0 [--dry]
"""
import json
import os
import shutil
import sys

import torch

from unicross.evaluation import read_results

D = "docs/runs/translate_zm_reference/thickness"
CK = "unicross/checkpoints/allegro/translate_z-"
run = sys.argv[1]
ck = torch.load(f"{run}/policy.pt", map_location="cpu", weights_only=False)
old = json.load(open(f"{CK}.json"))
if old["clone_of"] == ck["clone_of"]:  # run again after shipping: keep the record it replaced
    old = old["replaced"]
teacher = open(f"{D}/teacher.txt").read().strip()
assert ck["clone_of"] == f"seq:{teacher}", "the run is not a clone of teacher.txt"


def evaluation(path, limit, trials):
    r = read_results(path)
    return dict(file=path, objects="test", limit=limit, trials_per_object=trials, seed=0, summaries=r["summaries"])


def other_seed(s):
    out = dict(seed=s, command=open(f"{D}/clone_s{s}/command.txt").read().strip(),
               evaluations=[evaluation(f"{D}/clone_s{s}/report_test.json", 10, 5)])
    if os.path.exists(f"{D}/full/clone_s{s}_test_full.json.gz"):
        out["evaluations"].append(evaluation(f"{D}/full/clone_s{s}_test_full.json.gz", None, 25))
    return out


new = dict(
    skill="translate", axis="z-", hand="allegro", iteration=0, frames=ck["frames"], git_commit=ck["git_commit"],
    commits=ck["commits"], clone_of=ck["clone_of"],
    kind="dagger clone of a scripted finger sequence chosen per object by its width (a privileged teacher)",
    physics=old["physics"],
    commands=[
        "python docs/runs/translate_zm_reference/whole_set/search3.py docs/runs/translate_zm_reference/second_phase/"
        "chosen.txt runs/zm_thin --max-width 0.049 --generations 8 --per-group 12 --starts 4 --sigma1 0.006 "
        "--sigma2 0.010 --select-starts 4   # commit 2619504 (the script as committed there), 12 iterations: the "
        "two-phase sequence searched on the 61 training sticks under 4.9 cm; selection 181 of 244 against the "
        f"shipped sequence's 159 ({D}/search/); 11 min on 2 cores; the chosen one is {D}/chosen_thin.txt, and "
        f"{D}/teacher.txt runs it on sticks under 4.9 cm, the shipped sequence on the others",
        f"bash {D}/run.sh   # steps 3-5 of {D}/rule.txt: the teacher on the training sticks ({D}/teacher_train.txt), "
        f"the clone below, the full test protocol of the clone and of the teacher ({D}/full/)",
        f"python benchmarks/gait_clone.py --sequence '{teacher}' --mode translate_z- --limit 32 --trials 2 --rounds 6 "
        f"--beta 0.5 --workers 2 --seed 0 --out {run}  # commit {ck['git_commit'][:7]} with the width switch of "
        "unicross/sequences.py that 2619504 committed (uncommitted when it ran); the DAgger clone (6 rounds, "
        f"training objects only); log {D}/clone_s0/log.jsonl",
        f"unicross eval --policy {run}/policy.pt --protocol translate --axis z- --objects test --limit 10 "
        f"--trials-per-object 5 --seed 0 --workers 2 --out {D}/clone_s0/report_test.json   # the report's test cell",
        f"unicross eval --policy {run}/policy.pt --protocol translate --axis z- --objects test --workers 2 --seed 0 "
        f"--out runs/zm_thick_clone_full.json   # the full test protocol (200 objects x 25; the rule's), then gzip -9 "
        f"as {D}/full/clone_test_full.json.gz",
    ],
    hardware=old["hardware"], train_wall_s=ck["wall_s"],
    frames_note="control steps simulated over the clone's DAgger rounds (the sum of new_states in its log.jsonl); "
                "the searches (the shipped sequence's, and the thin-stick one's 12,288 training episodes of 50 steps) "
                "and the selections are not counted",
    shipping_rule=f"{D}/rule.txt",
    evaluations=[evaluation(f"{D}/clone_s0/report_test.json", 10, 5),
                 evaluation(f"{D}/full/clone_test_full.json.gz", None, 25)],
    baselines={"the teacher it copies (full test protocol)": evaluation(f"{D}/full/teacher_test_full.json.gz", None, 25),
               "the expert it replaces (full test protocol)": evaluation(
                   "docs/runs/student_test_full/test_translate_zm_translate_zm_phase2.json.gz", None, 25)},
    other_seeds=[other_seed(s) for s in (1, 2) if os.path.exists(f"{D}/clone_s{s}/command.txt")],
    seeds_pooled_test="the report's test cell (n = 100 each), seeds 0 / 1 / 2: 87 / 88 / 77% (252 of 300, 84.0%); the "
                      "full test protocol (5,000 each): 80.8 / 79.5 / 78.5% (11,942 of 15,000, 79.6% [79.0-80.3]), "
                      "each above the replaced expert paired by trial (+4.3, +2.9, +2.0 points); the two-phase "
                      "clones it replaces, three seeds on the report's cell: 82.0% of 300",
    replaced_because="on the full test protocol (5,000 trials, paired by trial) it does 80.8% [79.7-81.9] against "
                     "the replaced expert's 76.6% [75.4-77.7]: +4.3 points [+3.3, +5.3]",
    replaced=old,
)
if "--dry" not in sys.argv:
    shutil.copy(f"{run}/policy.pt", f"{CK}.pt")
    json.dump(new, open(f"{CK}.json", "w"), indent=1)
    print(f"wrote {CK}.pt and {CK}.json")
else:
    print(json.dumps({k: v for k, v in new.items() if k != "replaced"}, indent=1)[:3000])
