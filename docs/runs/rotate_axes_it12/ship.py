"""Ship the clone of an axis's gait searched under 12 iterations as allegro/rotate_AX (rule.txt step 4): copy its
policy and write the sidecar (the searches' commands, the held-out cells), the replaced record kept under
``replaced``. Refuses unless the rule's paired interval lies above 0: step 4's (paired.txt, written by run.sh), or
where step 4 missed, step 4b's on 360 fresh trials (paired_confirm.txt, confirm.sh); for z+ and y- (rule2.txt) step 4
is the 480 trials of evaluation seeds 0-3 (paired_480.txt, `confirm.sh AX 480`).

    python docs/runs/rotate_axes_it12/ship.py x- [--dry]
"""
import json
import os
import re
import shutil
import sys

import torch

from unicross.evaluation import read_results

AX = sys.argv[1]
D = f"docs/runs/rotate_axes_it12/{AX}"
RUN = f"runs/clone/{AX}_it12"
CK = f"unicross/checkpoints/allegro/rotate_{AX}"
HELDOUT = f"--protocol rotate --axis {AX} --objects test --limit 20 --trials-per-object 3 --seed 0 --workers 2"


def lower_end(path):
    """The lower end of the paired difference's 95% interval in a paired.py output."""
    return float(re.search(r"\[([+-]?[\d.]+),", open(path).read().split("difference", 1)[-1]).group(1))


RULE2 = AX in ("z+", "y-")
paired = open(f"{D}/paired.txt").read()
CONFIRM = f"{D}/paired_480.txt" if RULE2 else f"{D}/paired_confirm.txt"
confirmed = RULE2 or (lower_end(f"{D}/paired.txt") <= 0 and os.path.exists(CONFIRM))
low = lower_end(CONFIRM if confirmed else f"{D}/paired.txt")
step = "rule2.txt step 4" if RULE2 else "rule.txt step " + ("4b" if confirmed else "4")
if low <= 0:
    raise SystemExit(f"{step}: the paired interval's lower end is {low:+.1f}, not above 0; nothing ships")
candidate = json.load(open(f"{D}/candidate.json"))
ck = torch.load(f"{RUN}/policy.pt", map_location="cpu", weights_only=False)
assert ck["clone_of"] == candidate["log"], f"{RUN} is not a clone of {candidate['log']}"
old = json.load(open(f"{CK}.json"))
if old["clone_of"] == ck["clone_of"]:  # run again after shipping: keep the record it replaced
    old = old["replaced"]


def evaluation(path, seed=0):
    return dict(file=path, objects="test", limit=20, trials_per_object=3, seed=seed,
                summaries=read_results(path)["summaries"])


seeds = (1, 2, 3) if confirmed else ()


new = dict(
    skill="rotate", axis=AX, hand="allegro", iteration=0, frames=ck["frames"], git_commit=ck["git_commit"],
    commits=ck["commits"], clone_of=ck["clone_of"], kind="dagger clone of a scripted gait",
    commands=[
        f"bash docs/runs/rotate_axes_it12/run.sh {AX}   # searches A (the opposite axis's gaits run backwards), B (the "
        f"axis's own) and 2 (a second round from the better), the candidate {candidate['log']} (selection "
        f"success {100 * candidate['success']:.1f}% of its new training starts), its clone and the held-out cells; "
        f"logs {D}/search_{{A,B,2}}.log",
        open(f"{RUN}/command.txt").read().strip() + f"   # log {D}/clone_s0/log.jsonl",
        f"unicross eval --policy {RUN}/policy.pt {HELDOUT} --out {D}/clone_s0_test120",
        f"python docs/runs/paper_protocol/paired.py {D}/clone_s0_test120 {D}/shipped_test120 --skill rotate   "
        f"# {D}/paired.txt",
    ] + ([f"bash docs/runs/rotate_axes_it12/confirm.sh {AX} 480   # rule2.txt step 4: both policies under evaluation "
          f"seeds 1-3 too, paired over seeds 0-3 (480 trials) -> {CONFIRM}"] if RULE2 else
         [f"bash docs/runs/rotate_axes_it12/confirm.sh {AX}   # rule step 4b: both policies under evaluation seeds 1-3 "
          f"(360 fresh trials), paired -> {CONFIRM}"] if confirmed else []),
    hardware=old["hardware"], train_wall_s=ck["wall_s"],
    frames_note="control steps simulated over the clone's 8 DAgger rounds (the sum of new_states in its log.jsonl); "
                "the gait's searches are not counted",
    shipping_rule=f"docs/runs/rotate_axes_it12/{'rule2' if RULE2 else 'rule'}.txt",
    evaluations=[evaluation(f"{D}/clone_s0_test120")] + [evaluation(f"{D}/clone_s0_test120_seed{s}", s) for s in seeds],
    baselines={f"the expert it replaces (12 iterations, this machine), evaluation seed {s}":
               evaluation(f"{D}/shipped_test120" + (f"_seed{s}" if s else ""), s) for s in (0, *seeds)},
    replaced_because=(f"on the 480 held-out trials of evaluation seeds 0-3 (rule2.txt step 4), paired by trial against "
                      f"the replaced expert: {open(CONFIRM).read().strip()}" if RULE2 else
                      f"on the rule's 120 held-out trials, paired by trial against the replaced expert: {paired.strip()}"
                      + (f"; step 4 missed, and on 360 fresh trials (evaluation seeds 1-3, rule step 4b): "
                         f"{open(CONFIRM).read().strip()}" if confirmed else "")),
    replaced=old,
)
if "--dry" in sys.argv:
    print(json.dumps({k: v for k, v in new.items() if k != "replaced"}, indent=1)[:3000])
else:
    shutil.copy(f"{RUN}/policy.pt", f"{CK}.pt")
    json.dump(new, open(f"{CK}.json", "w"), indent=1)
    print(f"wrote {CK}.pt and {CK}.json")
