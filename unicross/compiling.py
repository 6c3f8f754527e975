"""``torch.compile`` for the per-step task math, behind one switch.

``UNICROSS_COMPILE=1`` (the default) compiles the math that follows the simulator's reads in each
step (``UniCrossEnv._step_math_eager``: ~400 small tensor ops, dispatch-bound on a CPU) into one
graph with static shapes; ``UNICROSS_COMPILE=0`` runs it eagerly (the test suite does: a cold
compile costs ~1-2 minutes per process and shape, the on-disk Inductor cache a few seconds after).
Compiled and eager agree to ~1e-6 per step (tests/test_compile.py).
"""
from __future__ import annotations

import os
from typing import Callable

import torch


RECOMPILE_LIMIT = 64


def compile_enabled() -> bool:
    """The ``UNICROSS_COMPILE`` switch: on unless set to 0/false/off."""
    return os.environ.get("UNICROSS_COMPILE", "1").strip().lower() not in ("0", "false", "off", "no")


def maybe_compile(fn: Callable) -> Callable:
    """``torch.compile(fn, fullgraph=True, dynamic=False)`` when the switch is on, else ``fn``.
    Compilation is lazy (at the first call) and shape-specialised: each hand (link count) and object
    shape kind gets its own graph, reused from the on-disk cache by later processes."""
    if not compile_enabled():
        return fn
    # one graph per (task class, configuration, shapes) met in a process; an evaluation process can
    # meet more than Dynamo's default of 8 (every skill, chains, disturbance settings, hands)
    cfg = torch._dynamo.config
    cfg.recompile_limit = max(cfg.recompile_limit, RECOMPILE_LIMIT)
    return torch.compile(fn, fullgraph=True, dynamic=False)
