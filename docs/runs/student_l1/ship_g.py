"""rule.txt screen G2: on a PASSED judge, ship seed 1 of screen G as allegro/student: copy its committed export
(``student_l1_rep3_w10ship_s1.pt``, made by ``unicross export runs/l1rep3w10ship_s1``), then rewrite the sidecar
(the replaced record under ``replaced``; seeds 2 and 3 under ``other_seeds``).

    python docs/runs/student_l1/ship_g.py [--dry]
"""
import json
import shutil
import sys

import torch

D = "docs/runs/student_l1"
CK = "unicross/checkpoints/allegro/student"
EXPORT = f"{D}/student_l1_rep3_w10ship_s1"
dry = "--dry" in sys.argv
old = json.load(open(f"{CK}.json"))
if old.get("rule", "").startswith(D):  # run again after shipping: keep the record it replaced
    old = old["replaced"]
ck = torch.load(f"{EXPORT}.pt", map_location="cpu", weights_only=False)
ck["wall_s"] = json.load(open(f"{EXPORT}.json"))["train_wall_s"]  # the stage's wall-clock, from the export's sidecar
STAGE = ("unicross distill --experts runs/experts1205x --out runs/l1rep3w10ship_s{s} --epochs 1500 "
         "--set model.init_policy=runs/student_1204_morning.pt --set optim.lr=1.0e-4 --set optim.warmup_frames=102400 "
         "--set env.object_limit=null --set collector.rollout_steps=256 --set optim.grad_steps=30 "
         "--set optim.batch_size=1024 --set buffer.capacity=300000 --set logging.checkpoint_every=25 --set seed={s} "
         "--set env.chain_share=0.15 --set 'optim.mode_weights={{rotate_x+: 30}}' --set optim.l1=0.01 "
         "--set 'env.mode_repeats={{rotate_x+: 3}}' --set 'optim.mode_weights={{rotate_x+: 10}}' "
         "--set model.init_policy=allegro/student")
commands = old["commands"] + [
    "mkdir -p runs/experts1205x; for m in grasp relocate rotate_x+ rotate_x- rotate_y+ rotate_y- rotate_z+ rotate_z- "
    "translate_z+ translate_z-; do mkdir -p runs/experts1205x/$m; cp unicross/checkpoints/allegro/$m.pt "
    "runs/experts1205x/$m/checkpoint.pt; done   # the ten shipped experts of commit fe6c582 (rotate x+ = the clone of "
    "the x+ finger sequence); docs/runs/student_l1/common.sh: experts_dir",
    STAGE.format(s=1) + f"   # commit {ck['git_commit'][:7]}, {ck['wall_s'] / 60:.0f} min on 2 cores ({D}/rule.txt "
    "screen G; later --set values override earlier ones: init = the student this replaces, x+ weight 10)",
    f"unicross export runs/l1rep3w10ship_s1 --out {EXPORT}.pt",
    f"python docs/runs/student_ft_1202b/seed_cells.py {EXPORT}.pt {D}/student_cells_rep3_w10ship_s1.json   "
    "# the report's test cells and long horizon, 7 min",
    f"python docs/runs/student_xp_drift/judge3.py {D}/student_cells_rep3_w10ship_s1.json "
    f"{D}/student_cells_rep3_w10ship_s2.json {D}/student_cells_rep3_w10ship_s3.json   # rule.txt G2",
    f"cp {EXPORT}.pt {CK}.pt   # python {D}/ship_g.py (this sidecar)",
]


def test_cells(c):
    return {m: v["cell"] for m, v in c["test"].items()}


def overall(c):
    return {k: v["overall"]["sr"] for k, v in c["long_horizon"]["summary"].items()}


cells = json.load(open(f"{D}/student_cells_rep3_w10ship_s1.json"))
seeds = []
for s in (2, 3):
    try:
        c = json.load(open(f"{D}/student_cells_rep3_w10ship_s{s}.json"))
    except FileNotFoundError:
        if dry:
            continue
        raise
    seeds.append(dict(seed=s, command=STAGE.format(s=s) + f" (export {D}/student_l1_rep3_w10ship_s{s}.pt); judged "
                      "pooled with seed 1, not chosen on", test_cells=test_cells(c), long_horizon_overall=overall(c)))
if not dry:
    shutil.copyfile(f"{EXPORT}.pt", f"{CK}.pt")
exp = json.load(open(f"{EXPORT}.json"))
new = dict(
    skill=exp["skill"], axis=exp["axis"], hand=exp["hand"], epoch=ck["epoch"], frames=old["frames"] + ck["frames"],
    distilled_modes=exp["distilled_modes"], git_commit=ck["git_commit"],
    commits=old["commits"] + [ck["git_commit"]], commands=commands, hardware=old["hardware"],
    train_wall_s=round(old["train_wall_s"] + ck["wall_s"], 1), stage_frames=ck["frames"],
    stage_wall_s=round(ck["wall_s"], 1),
    frames_note="frames and train_wall_s count every stage from the first DAgger run: the student this replaces "
                f"({old['frames']} frames, {old['train_wall_s']} s; its own frames_note under replaced) and this "
                "stage (stage_frames, stage_wall_s: 2026-12-06, rotate x+ walked three times with weight 10, l1 0.01, "
                "env.chain_share 0.15, on the ten shipped experts)",
    rule=f"{D}/rule.txt screen G (three fresh seeds pooled, docs/runs/student_xp_drift/judge3.py; seed 1 named "
         "before the runs)",
    teachers="the ten Allegro experts shipped at commit fe6c582 (rotate x+ = the clone of the x+ finger sequence)",
    test_cells=test_cells(cells), long_horizon_overall=overall(cells), other_seeds=seeds,
    long_horizon_note="the stage acts in long-horizon chains too (env.chain_share 0.15); per seed and pooled in "
                      f"{D}/README.md",
    replaced=old,
)
if dry:
    print(json.dumps({k: v for k, v in new.items() if k not in ("replaced", "commands")}, indent=1))
    print("\n".join(["commands (the last six):"] + commands[-6:]))
else:
    json.dump(new, open(f"{CK}.json", "w"), indent=1)
    print(f"wrote {CK}.pt and {CK}.json")
