"""Ship fine-tune seed 2 as allegro/translate_z+ (rule.txt amendment 2): copy its policy and write the sidecar
(commands, the confirmation's held-out cells and chains on evaluation seeds 4-7), the replaced record kept under
``replaced``. Refuses unless data/confirm/judge.txt (``python docs/runs/translate_zm_chain/judge.py
docs/runs/translate_zp_chain/data/confirm --mode translate_z+ --gain 3 --guard --seeds 4 5 6 7``) says SHIP.

    python docs/runs/translate_zp_chain/ship.py [--dry]
"""
import gzip
import json
import shutil
import sys

import torch

D = "docs/runs/translate_zp_chain"
C = f"{D}/data/confirm"
POLICY = f"{D}/data/ft_s2_policy.pt"
CK = "unicross/checkpoints/allegro/translate_z+"
SEEDS = (4, 5, 6, 7)
CELL = "--protocol translate --axis z+ --objects {o} {x}--limit 10 --trials-per-object 5 --seed {s} --workers 2"
CHAIN = "--sequence grasp,relocate,translate:z+ --objects test --limit 10 --trials-per-object 5 --seed {s}"
TRAIN = ("unicross train --skill translate --axis z+ --out runs/tzpchain/ft_s2 --total-frames 245760 --set seed=2 "
         "--set collector.frames_per_batch=4096 --set optim.kl_stop=0.032 --set model.init_log_std=-2.5 "
         "--set model.init_policy=allegro/translate_z+ --set optim.critic_warmup=5 "
         "--set env.grasp_dataset=runs/tzpchain/grasps_chain_train.pt")

judge = open(f"{C}/judge.txt").read()
if judge.strip().splitlines()[-1] != "SHIP":
    raise SystemExit(f"{C}/judge.txt does not say SHIP; nothing ships")
ck = torch.load(POLICY, map_location="cpu", weights_only=False)
meta = json.load(open(f"{D}/data/ft_s2_policy.json"))
old = json.load(open(f"{CK}.json"))
if old.get("shipping_rule") == f"{D}/rule.txt":  # run again after shipping: keep the record it replaced
    old = old["replaced"]


def load(name):
    return json.loads(gzip.decompress(open(f"{C}/{name}.gz", "rb").read()))


def evaluation(setting, who, s):
    d = load(f"{setting}_{who}_s{s}.json")
    return dict(file=f"{C}/{setting}_{who}_s{s}.json.gz", objects="unseen" if setting == "unseen" else "test",
                disturb=setting == "dist", limit=10, trials_per_object=5, seed=s, summaries=d["summaries"])


def chain(who, s):
    d = load(f"chain_{who}_s{s}.json")
    return dict(file=f"{C}/chain_{who}_s{s}.json.gz", sequence="grasp,relocate,translate:z+", objects="test",
                limit=10, trials_per_object=5, seed=s,
                summary={k: dict(overall=v["overall"], n=v["n"]) for k, v in d["summary"].items()})


new = dict(
    skill="translate", axis="z+", hand="allegro", iteration=meta["iteration"],
    frames=old["frames"] + meta["frames"], git_commit=meta["git_commit"], commits=old.get("commits", []) + meta["commits"],
    started_from=dict(policy="allegro/translate_z+ (the record under `replaced`)", frames_before=old.get("frames")),
    commands=old["commands"] + [
        "cp configs/grasps/allegro.pt runs/tzpchain/grasps_chain_train.pt && unicross grasps --chain grasp,relocate "
        "--policy experts:allegro --objects train-elongated --per-object 2 --out runs/tzpchain/grasps_chain_train.pt "
        "--append --seed 1   # half of the elongated training rows where the experts' grasp -> relocate chain leaves "
        "the hand (chain success 98.0%, 400 of 400 hold 2 s)",
        TRAIN + f"   # the PPO fine-tune, seed 2 of three ({D}/README.md), 322 s on 2 cores",
        f"unicross export runs/tzpchain/ft_s2 --out runs/tzpchain/ft_s2/policy.pt   # committed as {POLICY}",
    ] + [f"unicross chain --policy experts:runs/tzpchain/experts_c2 {CHAIN.format(s=s)}" for s in SEEDS]
      + [f"unicross eval --policy {POLICY} {CELL.format(o=o, x=x, s=s)}" for s in SEEDS
         for o, x in (("test", ""), ("unseen", ""), ("test", "--disturb "))]
      + [f"python docs/runs/translate_zm_chain/judge.py {C} --mode translate_z+ --gain 3 --guard --seeds 4 5 6 7   # SHIP"],
    hardware=meta["hardware"], train_wall_s=old["train_wall_s"] + meta["train_wall_s"],
    frames_note=f"the policy it started from ({old['frames']} frames, {old['train_wall_s'] / 60:.0f} min, under "
                f"`replaced`) and the fine-tune ({meta['frames']} frames, {meta['train_wall_s']:.0f} s), summed",
    shipping_rule=f"{D}/rule.txt (amendment 2)",
    evaluations=[evaluation("cell", "cand", s) for s in SEEDS],
    other_evaluations=[evaluation(st, "cand", s) for st in ("unseen", "dist") for s in SEEDS],
    chain_evaluations=[chain("cand", s) for s in SEEDS],
    baselines={**{f"the expert it replaces, {st}, evaluation seed {s}": evaluation(st, "shipped", s)
                  for st in ("cell", "unseen", "dist") for s in SEEDS},
               **{f"the expert it replaces chained, evaluation seed {s}": chain("shipped", s) for s in SEEDS}},
    replaced_because="rule.txt amendment 2, decided once on evaluation seeds 4-7: " + " ".join(judge.split()),
    replaced=old,
)
if "--dry" in sys.argv:
    print(json.dumps({k: v for k, v in new.items() if k != "replaced"}, indent=1)[:5000])
else:
    shutil.copy(POLICY, f"{CK}.pt")
    json.dump(new, open(f"{CK}.json", "w"), indent=1)
    print(f"wrote {CK}.pt and {CK}.json")
