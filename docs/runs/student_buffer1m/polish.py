"""Offline polish (a diagnostic): more Adam steps on a DAgger run's replay buffer, 10% of its rows held out of the fit.

    python docs/runs/student_buffer1m/polish.py RUN STEPS LR cos|const [OUT.pt]

Prints the student's per-mode MSE on the held-out rows at the start and after each quarter of STEPS (batch 1024, rows
weighted by the run's optim.mode_weights, lr LR constant or cosine to 0); OUT.pt: the run's checkpoint with the
polished weights (for drift.py or seed_cells.py). The held-out rows come from the same (object, mode) pairs as the
fitted ones: this measures the fit of the buffer, not what the student meets on new objects.
"""
import json
import math
import sys
import time

import torch
from torchrl.data import Bounded, LazyTensorStorage, TensorDictReplayBuffer

from unicross.rl.models import make_models, OBS_KEYS
from unicross import formulation as F
from unicross.rl.dagger import mode_weight_vector
torch.manual_seed(0)
run, steps, lr0, sched = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
ck = torch.load(f"{run}/checkpoint.pt", weights_only=False)
cfg = ck["config"]
rb = TensorDictReplayBuffer(storage=LazyTensorStorage(cfg["buffer"]["capacity"]), batch_size=1024)
rb.loads(f"{run}/{ck['replay_dir']}")
data = rb[:len(rb)]
n = data.shape[0]
perm = torch.randperm(n)
val, tr = data[perm[: n // 10]], data[perm[n // 10:]]
student, _, norm = make_models(ck["obs_dims"], ck["n_act"], Bounded(-1.0, 1.0, (ck["n_act"],)), cfg["model"])
student.load_state_dict(ck["policy"])
actor = student.module[0]
w = mode_weight_vector(cfg["optim"].get("mode_weights"))
print("weights", w.tolist(), "rows", n)
@torch.no_grad()
def evaluate():
    out = {}
    err = torch.cat([((actor(val[i:i+8192].select(*OBS_KEYS).clone())["loc"] - val[i:i+8192]["expert_action"]) ** 2).mean(-1)
                     for i in range(0, val.shape[0], 8192)])
    for i, m in enumerate(F.MODES):
        out[m] = float(err[val["mode"] == i].mean())
    return out
log = [dict(step=0, **evaluate())]
print(json.dumps({k: f"{v:.2e}" if isinstance(v, float) else v for k, v in log[-1].items()}))
opt = torch.optim.Adam(actor.parameters(), lr=lr0)
t0 = time.time()
for s in range(1, steps + 1):
    lr = lr0 * (0.5 * (1 + math.cos(math.pi * s / steps)) if sched == "cos" else 1.0)
    for g in opt.param_groups: g["lr"] = lr
    b = tr[torch.randint(0, tr.shape[0], (1024,))]
    pred = actor(b.select(*OBS_KEYS).clone())["loc"]
    err = ((pred - b["expert_action"]) ** 2).mean(-1)
    ww = w[b["mode"]]
    loss = (ww * err).sum() / ww.sum()
    opt.zero_grad(set_to_none=True); loss.backward(); opt.step()
    if s % (steps // 4) == 0:
        log.append(dict(step=s, **evaluate()))
        print(round(time.time() - t0), json.dumps({k: f"{v:.2e}" if isinstance(v, float) else v for k, v in log[-1].items()}), flush=True)
if len(sys.argv) > 5:
    ck2 = dict(ck); ck2["policy"] = student.state_dict(); torch.save(ck2, sys.argv[5])
