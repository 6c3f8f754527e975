"""Ship the student distilled on the width-switched translate z- expert as allegro/student (rule.txt step 6): export
the run, then rewrite the sidecar (the replaced record under ``replaced``).

    python docs/runs/translate_zm_reference/thickness/ship_student.py runs/ft_thick_s0 [--dry]
"""
import json
import subprocess
import sys

import torch

D = "docs/runs/translate_zm_reference/thickness"
CK = "unicross/checkpoints/allegro/student"
run = sys.argv[1]
dry = "--dry" in sys.argv
old = json.load(open(f"{CK}.json"))
if old.get("rule", "").startswith(D):  # run again after shipping: keep the record it replaced
    old = old["replaced"]
ck = torch.load(f"{run}/checkpoint.pt", map_location="cpu", weights_only=False)
STAGE = ("unicross distill --experts runs/experts1205 --out runs/ft_thick_s0 --epochs 1500 "
         "--set model.init_policy=runs/student_1204_morning.pt --set optim.lr=1.0e-4 --set optim.warmup_frames=102400 "
         "--set env.object_limit=null --set collector.rollout_steps=256 --set optim.grad_steps=30 "
         "--set optim.batch_size=1024 --set buffer.capacity=300000 --set logging.checkpoint_every=25 --set seed=0 "
         "--set env.chain_share=0.15")
i = next(k for k, c in enumerate(old["commands"]) if c.startswith("git show e10d371:"))
commands = old["commands"][:i + 1] + [
    "mkdir -p runs/experts1205; for m in grasp relocate rotate_x+ rotate_x- rotate_y+ rotate_y- rotate_z+ rotate_z- "
    "translate_z+; do mkdir -p runs/experts1205/$m; cp unicross/checkpoints/allegro/$m.pt "
    "runs/experts1205/$m/checkpoint.pt; done; mkdir -p runs/experts1205/translate_z-; cp runs/clone_zm_thick_s0/policy.pt "
    "runs/experts1205/translate_z-/checkpoint.pt   # the nine shipped experts of commit 55935e3 and the translate z- "
    f"clone of the width-switched teacher ({D}/README.md), shipped with this student",
    STAGE + f"   # commit {ck['git_commit'][:7]}, 20 min on 2 cores ({D}/rule.txt step 6: the shipped stage's recipe "
    "with the new translate z- teacher)",
    f"python docs/runs/student_ft_1202b/seed_cells.py runs/ft_thick_s0/checkpoint.pt {D}/student_cells_seed0.json   "
    f"# the report's test cells and long horizon, 7 min; judged by {D}/judge.py",
    f"unicross export runs/ft_thick_s0 --out {CK}.pt   # then python {D}/ship_student.py runs/ft_thick_s0 (this sidecar)",
]
cells = json.load(open(f"{D}/student_cells_seed0.json"))
before = 1382400 + 768000 + 768000, 4733.7 + 2348.8 + 1537.4  # the stages up to the 2026-12-04 morning student
if not dry:
    subprocess.run(["unicross", "export", run, "--out", f"{CK}.pt"], check=True)
new = dict(
    skill=old["skill"], axis=old["axis"], hand=old["hand"], epoch=ck["epoch"], frames=before[0] + ck["frames"],
    distilled_modes=old["distilled_modes"], git_commit=ck["git_commit"],
    commits=old["commits"][:5] + [ck["git_commit"]], commands=commands, hardware=old["hardware"],
    train_wall_s=round(before[1] + ck["wall_s"], 1), stage_frames=ck["frames"], stage_wall_s=round(ck["wall_s"], 1),
    frames_note="frames and train_wall_s count every stage from the first DAgger run (the student of 2026-11-28: "
                "1382400 frames, 4733.7 s; the stage of 2026-12-02: 768000 frames, 2348.8 s; the stage of 2026-12-04 "
                "morning: 768000 frames, 1537.4 s); stage_frames and stage_wall_s are the last stage's (2026-12-05 "
                "afternoon, the 49th session, env.chain_share 0.15, on the ten experts with the width-switched "
                "translate z- teacher's clone). It replaces a stage made from the same student with the same recipe "
                "on the two-phase z- expert",
    rule=f"{D}/rule.txt step 6 (one seed, judged cell by cell against the student it replaces: {D}/judge.py)",
    teachers="the nine Allegro experts shipped at commit 55935e3 and the translate z- clone of the width-switched "
             f"teacher ({D}/), shipped with this student",
    test_cells={m: v["cell"] for m, v in cells["test"].items()},
    long_horizon_overall={k: v["overall"]["sr"] for k, v in cells["long_horizon"]["summary"].items()},
    other_seeds=[],
    seeds_note="one seed: the recipe's other seeds were not run in the session that shipped it (the stage it replaces "
               "had three: docs/runs/student_yplus_repeat/)",
    long_horizon_note="the stage acts in long-horizon chains too (env.chain_share 0.15)",
    replaced=old,
)
if dry:
    print(json.dumps({k: v for k, v in new.items() if k != "replaced"}, indent=1)[:4000])
else:
    json.dump(new, open(f"{CK}.json", "w"), indent=1)
    print(f"wrote {CK}.pt and {CK}.json")
