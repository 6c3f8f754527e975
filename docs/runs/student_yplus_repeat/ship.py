"""Ship seed 0 of the stage from the shipped stage's own init (rule_init.txt, steps 3-4 of rule.txt) as
allegro/student: export the run, then rewrite the sidecar (the replaced record under ``replaced``).

    python docs/runs/student_yplus_repeat/ship.py runs/ft_init1204_s0 [--dry]
"""
import json
import subprocess
import sys

import torch

D = "docs/runs/student_yplus_repeat"
CK = "unicross/checkpoints/allegro/student"
run = sys.argv[1]
dry = "--dry" in sys.argv
old = json.load(open(f"{CK}.json"))
if old.get("rule", "").startswith(D):  # run again after shipping: keep the record it replaced
    old = old["replaced"]
ck = torch.load(f"{run}/checkpoint.pt", map_location="cpu", weights_only=False)
STAGE = ("unicross distill --experts runs/experts1204b --out runs/ft_init1204_s{s} --epochs 1500 "
         "--set model.init_policy=runs/student_1204_morning.pt --set optim.lr=1.0e-4 --set optim.warmup_frames=102400 "
         "--set env.object_limit=null --set collector.rollout_steps=256 --set optim.grad_steps=30 "
         "--set optim.batch_size=1024 --set buffer.capacity=300000 --set logging.checkpoint_every=25 --set seed={s} "
         "--set env.chain_share=0.15")
i = next(k for k, c in enumerate(old["commands"]) if c.startswith("unicross export runs/ft1204_s0 "))
commands = old["commands"][:i + 1] + [
    "git show e10d371:unicross/checkpoints/allegro/student.pt > runs/student_1204_morning.pt   # the student of "
    "2026-12-04 morning (the export of runs/ft1204_s0 above; the run used runs/ft1204_s0/checkpoint.pt, whose "
    "weights and observation statistics are the same), where the student this replaces was fine-tuned from",
    "mkdir -p runs/experts1204b; for m in grasp relocate rotate_x+ rotate_x- rotate_y+ rotate_y- rotate_z+ rotate_z- "
    "translate_z+ translate_z-; do mkdir -p runs/experts1204b/$m; cp unicross/checkpoints/allegro/$m.pt "
    "runs/experts1204b/$m/checkpoint.pt; done   # the ten shipped experts of commit dce6266 (translate z- = the clone of "
    "the two-phase sequence)",
    STAGE.format(s=0) + f"   # commit {ck['git_commit'][:7]}, 20 min on 2 cores ({D}/rule_init.txt)",
    f"python docs/runs/student_ft_1202b/seed_cells.py runs/ft_init1204_s0/checkpoint.pt {D}/cells_init_seed0.json   "
    "# the report's test cells and long horizon, 7 min",
    f"unicross export runs/ft_init1204_s0 --out {CK}.pt   # then python {D}/ship.py runs/ft_init1204_s0 (this sidecar)",
]
cells = json.load(open(f"{D}/cells_init_seed0.json"))


def test_cells(c):
    return {m: v["cell"] for m, v in c["test"].items()}


def overall(c):
    return {k: v["overall"]["sr"] for k, v in c["long_horizon"]["summary"].items()}


before = 1382400 + 768000 + 768000, 4733.7 + 2348.8 + 1537.4  # the stages up to the 2026-12-04 morning student
seeds = []
for s in (1, 2):
    try:
        c = json.load(open(f"{D}/cells_init_seed{s}.json"))
    except FileNotFoundError:
        if dry:
            continue
        raise
    seeds.append(dict(seed=s, command=STAGE.format(s=s) + " (weights not kept); reported, not chosen on",
                      test_cells=test_cells(c), long_horizon_overall=overall(c)))
if not dry:
    subprocess.run(["unicross", "export", run, "--out", f"{CK}.pt"], check=True)
exp = json.load(open(f"{CK}.json")) if not dry else dict(old)
new = dict(
    skill=exp["skill"], axis=exp["axis"], hand=exp["hand"], epoch=ck["epoch"], frames=before[0] + ck["frames"],
    distilled_modes=exp["distilled_modes"], git_commit=ck["git_commit"],
    commits=old["commits"][:5] + [ck["git_commit"]], commands=commands, hardware=old["hardware"],
    train_wall_s=round(before[1] + ck["wall_s"], 1), stage_frames=ck["frames"], stage_wall_s=round(ck["wall_s"], 1),
    frames_note="frames and train_wall_s count every stage from the first DAgger run (the student of 2026-11-28: "
                "1382400 frames, 4733.7 s; the stage of 2026-12-02: 768000 frames, 2348.8 s; the stage of 2026-12-04 "
                "morning: 768000 frames, 1537.4 s); stage_frames and stage_wall_s are the last stage's (2026-12-05, "
                "env.chain_share 0.15, on the ten experts with the two-phase translate z- teacher). The stage of "
                "2026-12-04 afternoon (the student this replaces) is not in this student's line",
    rule=f"{D}/rule_init.txt (steps 3-4 of rule.txt: three seeds pooled against the shipped stage's three)",
    teachers="the ten Allegro experts shipped at commit dce6266 (translate z- = the clone of the two-phase sequence)",
    test_cells=test_cells(cells), long_horizon_overall=overall(cells), other_seeds=seeds,
    long_horizon_note="the stage acts in long-horizon chains too (env.chain_share 0.15); per seed and pooled in "
                      f"{D}/README.md",
    replaced=old,
)
if dry:
    print(json.dumps({k: v for k, v in new.items() if k != "replaced"}, indent=1)[:4000])
else:
    json.dump(new, open(f"{CK}.json", "w"), indent=1)
    print(f"wrote {CK}.pt and {CK}.json")
