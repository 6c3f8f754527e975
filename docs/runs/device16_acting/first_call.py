"""Where a fresh process's first compiled step goes (issue #12: on the lent 16-core machines each
worker's first compiled call took ~40 s even when Inductor's cache hit; on the 2-core VM 1-7 s).

Makes the grasp env and resets it (which traces and compiles, or loads from the cache, the step
math), then times the first step (the same for the command math), all under cProfile; prints one
JSON object: the seconds, the Inductor settings that matter here, and the 45 functions with the
most cumulative time.

    python docs/runs/device16_acting/first_call.py            # the cache as it is
    TORCHINDUCTOR_COMPILE_THREADS=1 python .../first_call.py  # no compile worker pool
    CUDA_VISIBLE_DEVICES= python .../first_call.py            # no GPU in the process
"""
import cProfile
import io
import json
import os
import pstats
import time

import gymnasium as gym
import torch

import unicross  # noqa: F401  (registers the tasks)

prof = cProfile.Profile()
t_import = time.perf_counter()
prof.enable()
env = gym.make("UniCross-Grasp-v1", obs_mode="state_dict", render_backend="none", sim_backend="physx_cpu")
u = env.unwrapped
u.reset(seed=0)  # compiles (or loads) the step math
t_made = time.perf_counter()
u.step(torch.zeros(1, u.hand_spec.dof))  # compiles (or loads) the command math
prof.disable()
first = time.perf_counter() - t_made
t = time.perf_counter()
for _ in range(20):
    u.step(torch.zeros(1, u.hand_spec.dof))
later = (time.perf_counter() - t) / 20
s = io.StringIO()
pstats.Stats(prof, stream=s).sort_stats("cumulative").print_stats(70)
import torch._inductor.config as ic  # noqa: E402

print(json.dumps(dict(first_step_s=round(first, 2), later_step_ms=round(later * 1e3, 2),
                      make_and_reset_s=round(t_made - t_import, 2), cores=os.cpu_count(),
                      compile_threads=ic.compile_threads, torch=torch.__version__,
                      env={k: v for k, v in os.environ.items() if k.startswith(("TORCHINDUCTOR", "UNICROSS"))},
                      profile=s.getvalue().splitlines()[:100]), indent=1))
env.close()
