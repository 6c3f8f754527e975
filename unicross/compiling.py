"""``torch.compile`` for the per-step task math, behind one switch.

``UNICROSS_COMPILE=1`` (the default) compiles the tensor math of each step (``UniCrossEnv.
_command_math_eager``: action -> joint targets; ``_step_math_eager``: everything ``evaluate()``
computes after the simulator's reads, ~400 small ops that are dispatch-bound on a CPU) into one
graph each, with static shapes. ``UNICROSS_COMPILE=0`` runs them eagerly; the test suite does,
since a cold compile costs about a minute per process (Inductor's on-disk cache, by default under
``/tmp/torchinductor_$USER`` or ``$TORCHINDUCTOR_CACHE_DIR``, brings later processes to seconds).
Compiled and eager agree to 1e-5 after a step (tests/test_compile.py).

On the CPU the graph is called through Inductor's C++ wrapper and without its size asserts
(Dynamo's guards already check every input's shape before the graph runs): per call that saves
~100 us of Python around ~100 us of kernels (rotate: step math 339 -> 241 us, command math 120 ->
99 us, measured in one process, ``benchmarks/env_throughput.py``), for ~6 s more of cold compile.
"""
from __future__ import annotations

import functools
import os
import sys
import time
from typing import Callable

import torch

RECOMPILE_LIMIT = 64
# Inductor options of the CPU graphs (see the module docstring); GPU graphs keep the defaults
CPU_OPTIONS = {"cpp_wrapper": True, "size_asserts": False}
_ANNOUNCED = False


def compile_enabled() -> bool:
    """The ``UNICROSS_COMPILE`` switch: on unless set to 0/false/off/no."""
    return os.environ.get("UNICROSS_COMPILE", "1").strip().lower() not in ("0", "false", "off", "no")


def maybe_compile(fn: Callable, cpu: bool = True) -> Callable:
    """``torch.compile(fn, fullgraph=True, dynamic=False)`` when the switch is on, else ``fn``;
    ``cpu``: the graph runs on CPU tensors (``CPU_OPTIONS``).

    Compilation is lazy (at the first call) and specialised to the shapes and the task's
    configuration: one graph per task class, configuration and hand in a process, loaded from the
    on-disk cache when an earlier process compiled it. The first compile in a process says so on
    stderr with its duration. If the backend fails (e.g. no working C++ compiler), the function
    says so once and runs eagerly from then on."""
    if not compile_enabled():
        return fn
    # an evaluation process can meet more graphs than Dynamo's default of 8 (every skill, chains,
    # disturbance settings, hands)
    cfg = torch._dynamo.config
    cfg.recompile_limit = max(cfg.recompile_limit, RECOMPILE_LIMIT)
    compiled = torch.compile(fn, fullgraph=True, dynamic=False, options=CPU_OPTIONS if cpu else None)
    impl = [compiled]

    @functools.wraps(fn)
    def call(*args, **kwargs):
        global _ANNOUNCED
        announce = not _ANNOUNCED and impl[0] is compiled
        if announce:
            _ANNOUNCED = True
            print(f"[unicross] compiling the step math with torch.compile (pid {os.getpid()}; about a minute "
                  "the first time, seconds from the cache; UNICROSS_COMPILE=0 runs it eagerly)",
                  file=sys.stderr, flush=True)
        t = time.perf_counter()
        try:
            out = impl[0](*args, **kwargs)
        except torch._dynamo.exc.BackendCompilerFailed as e:  # e.g. no working C++ compiler
            if impl[0] is not compiled:
                raise
            impl[0] = fn
            print(f"[unicross] torch.compile failed ({str(e).strip().splitlines()[0][:200]}); running the step "
                  "math eagerly (install a C++ compiler, e.g. g++, or set UNICROSS_COMPILE=0 to skip the attempt)",
                  file=sys.stderr, flush=True)
            return fn(*args, **kwargs)
        if announce:
            print(f"[unicross] step math compiled in {time.perf_counter() - t:.1f} s (pid {os.getpid()})",
                  file=sys.stderr, flush=True)
        return out

    return call
