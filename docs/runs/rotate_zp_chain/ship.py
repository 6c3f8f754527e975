"""Ship the rotate z+ clone made from chain-aware starts as allegro/rotate_z+ (rule.txt): copy its policy and write the
sidecar (commands, the held-out cells of both bars), the replaced record kept under ``replaced``. Refuses unless
judge.txt (``python docs/runs/translate_zm_chain/judge.py docs/runs/rotate_zp_chain/data --mode rotate_z+ --gain 5``)
says SHIP.

    python docs/runs/rotate_zp_chain/ship.py [--dry]
"""
import gzip
import json
import shutil
import sys

import torch

D = "docs/runs/rotate_zp_chain"
RUN = "runs/clone/zp_chain_s0"
CK = "unicross/checkpoints/allegro/rotate_z+"
CELL = "--protocol rotate --axis z+ --objects test --limit 10 --trials-per-object 5 --seed {s} --workers 2"
CHAIN = "--sequence grasp,relocate,rotate:z+ --objects test --limit 10 --trials-per-object 5 --seed {s}"

judge = open(f"{D}/judge.txt").read()
if judge.strip().splitlines()[-1] != "SHIP":
    raise SystemExit(f"{D}/judge.txt does not say SHIP; nothing ships")
ck = torch.load(f"{RUN}/policy.pt", map_location="cpu", weights_only=False)
old = json.load(open(f"{CK}.json"))
if old.get("shipping_rule") == f"{D}/rule.txt":  # run again after shipping: keep the record it replaced
    old = old["replaced"]
assert ck["clone_of"] == old["clone_of"], "the candidate must clone the shipped expert's gait (only the starts differ)"


def load(name):
    return json.loads(gzip.decompress(open(f"{D}/data/{name}.gz", "rb").read()))


def evaluation(who, s):
    d = load(f"cell_{who}_s{s}.json")
    return dict(file=f"{D}/data/cell_{who}_s{s}.json.gz", objects="test", limit=10, trials_per_object=5, seed=s,
                summaries=d["summaries"])


def chain(who, s):
    d = load(f"chain_{who}_s{s}.json")
    return dict(file=f"{D}/data/chain_{who}_s{s}.json.gz", sequence="grasp,relocate,rotate:z+", objects="test",
                limit=10, trials_per_object=5, seed=s,
                summary={k: dict(overall=v["overall"], n=v["n"]) for k, v in d["summary"].items()})


held = load("heldout.json")
new = dict(
    skill="rotate", axis="z+", hand="allegro", iteration=0, frames=ck["frames"], git_commit=ck["git_commit"],
    commits=ck["commits"], clone_of=ck["clone_of"], kind="dagger clone of a scripted gait",
    commands=[
        "cp configs/grasps/allegro.pt runs/zpchain/grasps_chain_train.pt && unicross grasps --chain grasp,relocate "
        "--policy experts:allegro --objects train-wrappable --limit 8 --per-object 2 --out runs/zpchain/grasps_chain_train.pt "
        f"--append --seed 1   # the clone's starts: 32 chain rows beside the 32 grasp rows of its 16 objects; chain "
        f"success 91.4%, 32 of 32 hold 2 s; committed as {D}/grasps_chain_train.pt",
        open(f"{RUN}/command.txt").read().strip() + f"   # log {D}/data/clone_s0_log.jsonl; held out (test, first 20 "
        f"per group x 3, seed 0) {held['success']} of {held['n']} ({D}/data/heldout.json.gz)",
    ] + [f"unicross eval --policy {RUN}/policy.pt {CELL.format(s=s)} --out runs/zpchain/cell_cand_s{s}.json" for s in range(4)]
      + [f"unicross chain --policy experts:runs/zpchain/experts_cand {CHAIN.format(s=s)} --out runs/zpchain/chain_cand_s{s}.json"
         "   # experts_cand: the ten shipped experts, rotate_z+ the candidate" for s in range(4)]
      + [f"python docs/runs/translate_zm_chain/judge.py {D}/data --mode rotate_z+ --gain 5   # {D}/judge.txt: SHIP"],
    hardware=old["hardware"], train_wall_s=ck["wall_s"],
    frames_note="control steps simulated over the clone's 8 DAgger rounds (the sum of new_states in its log.jsonl); "
                "the gait's searches and the chain states are not counted",
    shipping_rule=f"{D}/rule.txt",
    evaluations=[evaluation("cand", s) for s in range(4)],
    chain_evaluations=[chain("cand", s) for s in range(4)],
    baselines={**{f"the expert it replaces, evaluation seed {s}": evaluation("shipped", s) for s in range(4)},
               **{f"the expert it replaces chained, evaluation seed {s}": chain("shipped", s) for s in range(4)}},
    replaced_because="rule.txt, decided once on evaluation seeds 0-3: " + " ".join(judge.split()),
    replaced=old,
)
if "--dry" in sys.argv:
    print(json.dumps({k: v for k, v in new.items() if k != "replaced"}, indent=1)[:4000])
else:
    shutil.copy(f"{RUN}/policy.pt", f"{CK}.pt")
    json.dump(new, open(f"{CK}.json", "w"), indent=1)
    print(f"wrote {CK}.pt and {CK}.json")
