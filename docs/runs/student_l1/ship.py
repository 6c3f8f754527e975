"""Ship seed 0 of the weight-30 stage with optim.l1 = 0.01 as allegro/student (rule.txt step 4, only when judge.txt
says PASSED): export the run, then rewrite the sidecar (the replaced record under ``replaced``, the other two seeds
under ``other_seeds``).

    python docs/runs/student_l1/ship.py runs/l1_w30_s0 [--dry]
"""
import json
import subprocess
import sys

import torch

D = "docs/runs/student_l1"
CK = "unicross/checkpoints/allegro/student"
run = sys.argv[1]
dry = "--dry" in sys.argv
if "PASSED" not in open(f"{D}/judge.txt").read():
    sys.exit(f"{D}/judge.txt does not say PASSED: rule.txt ships nothing")
old = json.load(open(f"{CK}.json"))
if old.get("rule", "").startswith(D):  # run again after shipping: keep the record it replaced
    old = old["replaced"]
ck = torch.load(f"{run}/checkpoint.pt", map_location="cpu", weights_only=False)


def stage(seed):
    return ("unicross distill --experts runs/experts1205x --out runs/l1_w30_s%d --epochs 1500 "
            "--set model.init_policy=runs/student_1204_morning.pt --set optim.lr=1.0e-4 "
            "--set optim.warmup_frames=102400 --set env.object_limit=null --set collector.rollout_steps=256 "
            "--set optim.grad_steps=30 --set optim.batch_size=1024 --set buffer.capacity=300000 "
            "--set logging.checkpoint_every=25 --set seed=%d --set env.chain_share=0.15 "
            "--set 'optim.mode_weights={rotate_x+: 30}' --set optim.l1=0.01" % (seed, seed))


i = next(k for k, c in enumerate(old["commands"]) if c.startswith("git show e10d371:"))
commands = old["commands"][:i + 1] + [
    "mkdir -p runs/experts1205x; for m in grasp relocate rotate_x+ rotate_x- rotate_y+ rotate_y- rotate_z+ rotate_z- "
    "translate_z+ translate_z-; do mkdir -p runs/experts1205x/$m; cp unicross/checkpoints/allegro/$m.pt "
    "runs/experts1205x/$m/checkpoint.pt; done   # the ten shipped experts (unchanged since commit fe6c582)",
    stage(0) + f"   # commit {ck['git_commit'][:7]}, {ck['wall_s'] / 60:.0f} min on 2 cores ({D}/rule.txt, run.sh)",
    f"python docs/runs/student_ft_1202b/seed_cells.py {D}/student_l1_s0.pt {D}/student_cells_s0.json   "
    f"# the report's test cells and long horizon, 7 min; seeds 0-2 pooled by docs/runs/student_xp_drift/judge3.py "
    f"({D}/judge.txt)",
    f"unicross export runs/l1_w30_s0 --out {CK}.pt   # then python {D}/ship.py runs/l1_w30_s0 (this sidecar)",
]


def cells(seed):
    c = json.load(open(f"{D}/student_cells_s{seed}.json"))
    return ({m: v["cell"] for m, v in c["test"].items()},
            {k: v["overall"]["sr"] for k, v in c["long_horizon"]["summary"].items()})


before = 1382400 + 768000 + 768000, 4733.7 + 2348.8 + 1537.4  # the stages up to the 2026-12-04 morning student
if not dry:
    subprocess.run(["unicross", "export", run, "--out", f"{CK}.pt"], check=True)
test0, lh0 = cells(0)
others = []
for s in (1, 2):
    t, lh = cells(s)
    others.append(dict(seed=s, command=stage(s) + " (weights in " + f"{D}/student_l1_s{s}.pt); reported, not chosen on",
                       test_cells=t, long_horizon_overall=lh, file=f"{D}/student_cells_s{s}.json"))
new = dict(
    skill=old["skill"], axis=old["axis"], hand=old["hand"], epoch=ck["epoch"], frames=before[0] + ck["frames"],
    distilled_modes=old["distilled_modes"], git_commit=ck["git_commit"],
    commits=old["commits"][:5] + [ck["git_commit"]], commands=commands, hardware=old["hardware"],
    train_wall_s=round(before[1] + ck["wall_s"], 1), stage_frames=ck["frames"], stage_wall_s=round(ck["wall_s"], 1),
    frames_note="frames and train_wall_s count every stage from the first DAgger run (the student of 2026-11-28: "
                "1382400 frames, 4733.7 s; the stage of 2026-12-02: 768000 frames, 2348.8 s; the stage of 2026-12-04 "
                "morning: 768000 frames, 1537.4 s); stage_frames and stage_wall_s are the last stage's (2026-12-05, "
                "the 55th session: env.chain_share 0.15, rotate x+ weighted 30, optim.l1 0.01, on the ten shipped "
                "experts). It replaces a stage made from the same student without the x+ weight and without l1",
    rule=f"{D}/rule.txt (three seeds pooled by docs/runs/student_xp_drift/judge3.py: every mode within 5 points of "
         f"its expert's cell, long horizon within 5 of the replaced student's; {D}/judge.txt)",
    teachers="the ten Allegro experts shipped at commit fe6c582 (rotate x+ = the DAgger clone of the x+ finger sequence)",
    test_cells=test0, long_horizon_overall=lh0, other_seeds=others,
    long_horizon_note="the stage acts in long-horizon chains too (env.chain_share 0.15)",
    replaced=old,
)
if dry:
    print(json.dumps({k: v for k, v in new.items() if k != "replaced"}, indent=1)[:4000])
else:
    json.dump(new, open(f"{CK}.json", "w"), indent=1)
    print(f"wrote {CK}.pt and {CK}.json")
