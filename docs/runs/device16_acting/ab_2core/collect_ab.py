"""Collection only, 2 env worker processes (or N: first argument), the workers acting through
GaussianHead.acting_fn ("fast") or calling the module's forward ("module", the code before it),
two collectors alive side by side, alternating, 8 pairs of 256-step batches per worker:

    python docs/runs/device16_acting/ab_2core/collect_ab.py 2
"""
import statistics
import sys
import time

import torch

from unicross.config import load_config
from unicross.rl.collector import LeanCollector
from unicross.rl.models import make_models
from unicross.rl.ppo import env_kwargs_for


class Plain(torch.nn.Module):
    """The actor without ``acting_fn``: the worker calls its forward."""

    def __init__(self, head):
        super().__init__()
        self.head = head

    def forward(self, h, o, g):
        return self.head(h, o, g)


def main():
    workers, horizon = int(sys.argv[1]) if len(sys.argv) > 1 else 2, 256
    kw = env_kwargs_for("grasp", None, "allegro", load_config("ppo")["env"])
    cs = {}
    for name in ("fast", "module"):
        c = LeanCollector("UniCross-Grasp-v1", kw, workers, horizon, seed=0)
        head = make_models(c.dims, c.n_act, None, load_config("ppo")["model"])[0].module[0].module
        c.set_actor(head if name == "fast" else Plain(head))
        c.collect()
        cs[name] = c
    ratios = []
    for i in range(8):
        r = {}
        for name in (("fast", "module") if i % 2 == 0 else ("module", "fast")):
            t = time.perf_counter()
            cs[name].collect()
            r[name] = workers * horizon / (time.perf_counter() - t)
        ratios.append(r["fast"] / r["module"])
        print({k: round(v, 1) for k, v in r.items()}, round(ratios[-1], 3), flush=True)
    print("median fast/module", round(statistics.median(ratios), 3), "fast faster in",
          sum(x > 1 for x in ratios), "of", len(ratios))
    for c in cs.values():
        c.close()


if __name__ == "__main__":
    main()
