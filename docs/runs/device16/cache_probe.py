"""Does Inductor's on-disk cache serve a second process? A toy GraphMethod (the CPU step-math path)
and a toy torch.compile function with the step math's options; prints the cache counters.
    python docs/runs/device16/cache_probe.py   (twice: the second run should report hits)"""
import importlib.util
import os
import time

import torch

from torch._dynamo.utils import counters

# unicross/compiling.py alone (it needs torch only), without the package's other imports
spec = importlib.util.spec_from_file_location("compiling", os.path.join(os.getcwd(), "unicross", "compiling.py"))
compiling = importlib.util.module_from_spec(spec)
spec.loader.exec_module(compiling)
CPU_OPTIONS, GraphMethod = compiling.CPU_OPTIONS, compiling.GraphMethod


class Toy:
    def __init__(self):
        self.a = torch.linspace(0, 1, 64).reshape(8, 8)
        self.step_math = GraphMethod(self, Toy._math)

    def _math(self, x):
        self.a = torch.sin(self.a) + x.cos() * 2
        return (self.a @ x).tanh().sum(-1)


def f(x):
    return (torch.sin(x) @ x.T).relu().sum(-1)


t = time.perf_counter()
toy = Toy()
toy.step_math(torch.ones(8, 8))
t1 = time.perf_counter()
torch.compile(f, fullgraph=True, dynamic=False, options=CPU_OPTIONS)(torch.ones(8, 8))
t2 = time.perf_counter()
from torch._inductor import config as ic  # noqa: E402
try:
    from torch._inductor.runtime.cache_dir_utils import cache_dir
    where = cache_dir()
except Exception as e:  # noqa: BLE001
    where = repr(e)
print(f"torch {torch.__version__}: GraphMethod {t1 - t:.1f} s, torch.compile {t2 - t1:.1f} s; fx_graph_cache="
      f"{ic.fx_graph_cache} force_disable_caches={torch.compiler.config.force_disable_caches} cache_dir={where}")
print({k: dict(v) for k, v in counters.items() if k in ("inductor", "aot_autograd") and v})
