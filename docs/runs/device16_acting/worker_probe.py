"""Where a training worker's step goes beyond the env's own (issue #12), in one process, interleaved:
one env alone (scaling.py's single-env rate: task.step, small random actions, resets), and the same
task stepped by Rollout.collect with the untrained policy of configs/ppo.yaml acting through
GaussianHead.acting_fn ("fast") or the module's forward ("module"), the actor's in-loop time timed.

    python docs/runs/device16_acting/worker_probe.py [reps] [> out.json]   (the device run copies it beside scaling.py)
"""
import json
import os
import statistics
import sys
import time

import torch

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))
from scaling import single_env_rate  # noqa: E402

from unicross.config import load_config  # noqa: E402
from unicross.rl.collector import Rollout, make_buffer  # noqa: E402
from unicross.rl.models import make_models  # noqa: E402
from unicross.rl.ppo import env_kwargs_for  # noqa: E402

torch.set_num_threads(1)
reps = int(sys.argv[1]) if len(sys.argv) > 1 else 6
T = 256
kw = env_kwargs_for("grasp", None, "allegro", load_config("ppo")["env"])
r = Rollout("UniCross-Grasp-v1", dict(kw, sim_backend="physx_cpu", num_envs=1), 0)
head = make_models(r.dims, r.n_act, None, load_config("ppo")["model"])[0].module[0].module
spent = [0.0]


def timed(f):
    def g(*a):
        t = time.perf_counter()
        out = f(*a)
        spent[0] += time.perf_counter() - t
        return out
    return g


class Fast(torch.nn.Module):
    def acting_fn(self):
        return timed(head.acting_fn())


fast, module = Fast(), timed(head)
buf = make_buffer(1, T, r.dims, r.n_act)
r.set_actor(fast)
r.collect(buf)
rows = []
for i in range(reps):
    row = {"single_env": single_env_rate(600, seed=i)}
    for name, actor in (("fast", fast), ("module", module)) if i % 2 == 0 else (("module", module), ("fast", fast)):
        r.set_actor(actor)
        spent[0] = 0.0
        t = time.perf_counter()
        r.collect(buf)
        row[name] = T / (time.perf_counter() - t)
        row[name + "_actor_ms"] = spent[0] / T * 1e3
    rows.append(row)
    print(json.dumps({k: round(v, 3) for k, v in row.items()}), file=sys.stderr, flush=True)
med = {k: round(statistics.median(r_[k] for r_ in rows), 3) for k in rows[0]}
med["fast_vs_single"] = round(med["fast"] / med["single_env"], 3)
med["module_vs_single"] = round(med["module"] / med["single_env"], 3)
print(json.dumps(dict(cores=os.cpu_count(), compile=os.environ.get("UNICROSS_COMPILE", "1"), reps=reps,
                      steps_per_rep=T, median=med, rows=rows), indent=1))
