"""The per-step task math compiled, behind one switch.

``UNICROSS_COMPILE=1`` (the default) compiles the tensor math of each step (``UniCrossEnv.
_command_math_eager``: action -> joint targets; ``_step_math_eager``: everything ``evaluate()``
computes after the simulator's reads, ~400 small ops that are dispatch-bound on a CPU) into one
graph each, with static shapes. ``UNICROSS_COMPILE=0`` runs them eagerly; the test suite does,
since a cold compile costs about a minute per process (Inductor's on-disk cache, by default under
``/tmp/torchinductor_$USER`` or ``$TORCHINDUCTOR_CACHE_DIR``, brings later processes to seconds).
Compiled and eager agree to 1e-5 after a step (tests/test_compile.py).

On the CPU (:class:`GraphMethod`) the method is traced once per task as a pure function of its
arguments and the task's tensor state and compiled by Inductor without Dynamo: Dynamo re-checked
~700 guards and replayed the method's attribute writes in Python at every call, ~250 us per call
around ~140 us of kernels (rotate, step math). The graph runs through Inductor's C++ wrapper
without its size asserts; one C++ check of the inputs' shapes, strides and dtypes guards it.
On the GPU, or with ``UNICROSS_COMPILE=torch``, the methods go through ``torch.compile``
(:func:`maybe_compile`).
"""
from __future__ import annotations

import functools
import os
import sys
import time
import weakref
from typing import Callable, List, Optional

import torch
import torch.utils._pytree as pytree

RECOMPILE_LIMIT = 64
# Inductor options of the CPU graphs (see the module docstring); GPU graphs keep the defaults
CPU_OPTIONS = {"cpp_wrapper": True, "size_asserts": False}
_ANNOUNCED = False


def compile_enabled() -> bool:
    """The ``UNICROSS_COMPILE`` switch: on unless set to 0/false/off/no."""
    return os.environ.get("UNICROSS_COMPILE", "1").strip().lower() not in ("0", "false", "off", "no")


def compile_with_dynamo() -> bool:
    """``UNICROSS_COMPILE=torch``: the CPU step math through ``torch.compile`` (Dynamo) instead of
    :class:`GraphMethod` (slower per call; for comparisons, e.g. ``benchmarks/env_throughput.py``)."""
    return os.environ.get("UNICROSS_COMPILE", "1").strip().lower() == "torch"


def _announce_start() -> bool:
    global _ANNOUNCED
    if _ANNOUNCED:
        return False
    _ANNOUNCED = True
    print(f"[unicross] compiling the step math (pid {os.getpid()}; about a minute the first time, seconds from "
          "the cache; UNICROSS_COMPILE=0 runs it eagerly)", file=sys.stderr, flush=True)
    return True


def _records_dir():
    """Inductor's cache directory (``TORCHINDUCTOR_CACHE_DIR`` or its default), where
    :func:`settle_vec_isa` keeps its record (an import error there leaves the probes as they are)."""
    from pathlib import Path
    from torch._inductor.runtime.cache_dir_utils import cache_dir
    return Path(cache_dir())


@functools.cache
def settle_vec_isa() -> bool:
    """Runs Inductor's base probes of the machine's SIMD instruction sets once per machine, not once
    per process; True when this process skips them.

    Before its first CPU compile, Inductor checks which of the instruction sets the CPU reports
    (AVX2, AVX-512, AMX, ...) the C++ compiler and torch support, by building a test library for each
    and loading it in a child Python; up to torch 2.12 each child imports torch (~8 s each on the
    lent 16-core machines with torch 2.11, where a fresh worker spent 60-100 s before its first step
    with every graph in Inductor's cache: docs/runs/device16_render). The first process on a machine
    runs the probes and records their outcome in Inductor's cache directory (``unicross_vec_isa_*.json``),
    keyed by torch, Python, the C++ compiler's name (not its version: delete the record after changing
    compilers; a stale one can only make a compile fail, which runs the math eagerly as any compile
    error does) and the sets the CPU reports; a later process that finds every reported set
    passed sets ``torch._inductor.config.cpp.vec_isa_ok`` (the probes' own switch), which answers the
    base probe of each set without building anything. So does the first process once it has probed,
    so that all compile under one configuration (Inductor's cache keys include it). The sets' extra
    probes (AVX-512 VNNI and bf16, AMX) do not read the switch: :func:`_remember_probe_builds`
    answers those from the successes an earlier process recorded (also where ``vec_isa_ok`` is set).
    Measured with the switch alone: a fresh process's probes 1.5 -> 0.35 s on the 2-core VM (torch
    2.13), 10 -> 6 child processes (89-102 -> 61 s to the first step, one run each) on a lent
    machine. Nothing changes where a probe failed, where ``vec_isa_ok`` or
    ``TORCHINDUCTOR_VEC_ISA_OK`` is already set (beyond the remembered builds), or off x86."""
    import hashlib
    import json
    import platform
    from unicross.config import atomic_write
    try:
        from torch._inductor import config as ic
        from torch._inductor import cpu_vec_isa as isa
        if platform.machine() not in ("x86_64", "AMD64"):
            return False
        root = _records_dir()
        _remember_probe_builds(isa, root, [torch.__version__, sys.executable, str(ic.cpp.cxx)])
        if ic.cpp.vec_isa_ok is not None:
            return False
        flags = isa.x86_isa_checker()
        claimed = [str(v) for v in isa.supported_vec_isa_list if all(f in flags for f in str(v).split())]
        key = hashlib.sha256(json.dumps([torch.__version__, sys.executable, str(ic.cpp.cxx), claimed]).encode())
        record = root / f"unicross_vec_isa_{key.hexdigest()[:16]}.json"
        try:
            passed = json.loads(record.read_text())["passed"]
        except (OSError, ValueError, KeyError, TypeError):
            passed = [str(v) for v in isa.valid_vec_isa_list()]  # the probes, in this process
            text = json.dumps(dict(torch=torch.__version__, claimed=claimed, passed=passed))
            atomic_write(record, lambda tmp: tmp.write_text(text))
    except Exception:  # an optimisation over torch internals: never a reason to fail a compile
        return False
    if passed != claimed:
        return False
    ic.cpp.vec_isa_ok = True
    return True


def _remember_probe_builds(isa, root, machine: list) -> None:
    """Makes ``VecISA.check_build`` (Inductor's build-and-load probe of one instruction set's code)
    remember its successes per machine: a marker file in ``root`` per (``machine``, set, compiler
    flags, probe code), written after a probe passed; a later process that finds the marker answers
    True without building or starting a child. This covers the sets' extra probes that
    ``cpp.vec_isa_ok`` does not answer (AVX-512 VNNI and bf16, AMX, AMX-fp16; six child processes,
    ~50 s, in a warm worker's start on the lent machines with torch 2.11: docs/runs/device16_render).
    A failed probe is not remembered (it may have been a timeout), so it runs again in each process.
    Installed once per process, on the class, for every set."""
    import hashlib
    import json
    from unicross.config import atomic_write
    original = isa.VecISA.check_build
    if getattr(original, "_unicross_remembers", False):
        return

    def check_build(self, code: str) -> bool:
        key = json.dumps(machine + [type(self).__name__, self.build_arch_flags(), code])
        mark = root / f"unicross_isa_build_{hashlib.sha256(key.encode()).hexdigest()[:16]}.ok"
        if mark.is_file():
            return True
        ok = original(self, code)
        if ok:
            atomic_write(mark, lambda tmp: tmp.write_text(key))
        return ok

    check_build._unicross_remembers = True
    isa.VecISA.check_build = check_build


def _fall_back(e: Exception) -> None:
    print(f"[unicross] compiling the step math failed ({str(e).strip().splitlines()[0][:200]}); running it "
          "eagerly (install a C++ compiler, e.g. g++, or set UNICROSS_COMPILE=0 to skip the attempt)",
          file=sys.stderr, flush=True)


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
        announce = impl[0] is compiled and _announce_start()
        t = time.perf_counter()
        if announce and cpu:
            settle_vec_isa()
        try:
            out = impl[0](*args, **kwargs)
        except torch._dynamo.exc.BackendCompilerFailed as e:  # e.g. no working C++ compiler
            if impl[0] is not compiled:
                raise
            impl[0] = fn
            _fall_back(e)
            return fn(*args, **kwargs)
        if announce:
            print(f"[unicross] step math compiled in {time.perf_counter() - t:.1f} s (pid {os.getpid()})",
                  file=sys.stderr, flush=True)
        return out

    return call


def _is_state(v) -> bool:
    """A task attribute the compiled graph takes as input and may write: a tensor, or a registered
    pytree (tuples, lists, dicts, ``formulation.Relational``) of tensors only."""
    if torch.is_tensor(v):
        return True
    if isinstance(v, (str, bytes)) or pytree.tree_is_leaf(v):
        return False
    leaves = pytree.tree_leaves(v)
    return bool(leaves) and all(torch.is_tensor(x) for x in leaves)


class _InputGuard:
    """Checks that a call's inputs have the shapes, strides, dtypes and devices the graph was traced
    with (~10 us for the step math's ~40 inputs). Inputs may alias one another (a read that is also
    task state; the graph never writes into its inputs, so that is harmless): each aliasing pattern
    met gets Dynamo's C++ tensor check of its distinct tensors after an identity check of the repeats
    (the C++ check refuses repeated tensors); the same check in Python serves where it is missing."""

    def __init__(self, tensors: List[torch.Tensor]):
        self.sig = [(t.shape, t.stride(), t.dtype, t.device) for t in tensors]
        self.fast = []  # [(repeats, distinct positions, C++ check)], one per aliasing pattern met
        self._add(tensors)

    def _add(self, ts) -> None:
        if len(self.fast) >= 4:
            return
        first, repeats = {}, []
        for i, t in enumerate(ts):
            if id(t) in first:
                repeats.append((i, first[id(t)]))
            else:
                first[id(t)] = i
        unique = sorted(first.values())
        try:
            from torch._C._dynamo.guards import TensorGuards
            check = TensorGuards(*[ts[i] for i in unique], dynamic_dims_sizes=[list(ts[i].shape) for i in unique],
                                 dynamic_dims_strides=[list(ts[i].stride()) for i in unique]).check
        except Exception:  # pragma: no cover - a torch without Dynamo's C++ guards
            return
        self.fast.append((repeats, unique if repeats else None, check))

    def slow(self, ts) -> bool:
        return len(ts) == len(self.sig) and all(
            (t.shape, t.stride(), t.dtype, t.device) == s for t, s in zip(ts, self.sig))

    def __call__(self, ts: list) -> bool:
        if len(ts) == len(self.sig):
            for repeats, unique, check in self.fast:
                if unique is None:
                    if check(*ts):
                        return True
                elif all(ts[i] is ts[j] for i, j in repeats) and check(*[ts[i] for i in unique]):
                    return True
        if self.slow(ts):
            self._add(ts)  # a new aliasing pattern of the same tensors
            return True
        return False


def _unflattener(spec) -> Callable[[list], object]:
    """``leaves -> pytree`` for ``spec`` as one generated expression (~10x faster than
    ``pytree.tree_unflatten`` for the step math's outputs): dicts, tuples and lists as literals,
    other registered nodes (``formulation.Relational``) through their own unflatten function."""
    names, counter = {}, [0]

    def expr(sp) -> str:
        if sp.is_leaf():
            counter[0] += 1
            return f"L[{counter[0] - 1}]"
        kids = [expr(c) for c in sp.children()]
        if sp.type is dict:
            return "{" + ", ".join(f"{k!r}: {v}" for k, v in zip(sp.context, kids)) + "}"
        if sp.type is tuple:
            return "(" + "".join(f"{v}, " for v in kids) + ")"
        if sp.type is list:
            return "[" + ", ".join(kids) + "]"
        k = len(names)
        names[f"_u{k}"], names[f"_c{k}"] = pytree.SUPPORTED_NODES[sp.type].unflatten_fn, sp.context
        return f"_u{k}([{', '.join(kids)}], _c{k})"

    return eval(f"lambda L: {expr(spec)}", names)  # noqa: S307 - generated from the spec's own types and keys


def _refuse_input_writes(gm, name: str, arg_names: List[str]) -> None:
    """The traced graph must not write into its inputs (the task's tensors are read, and what the
    method assigns comes back as outputs): raises naming the input, which an in-place write such
    as ``self.x[:, 0] = v`` causes (write ``self.x = torch.cat(...)`` or a ``where`` instead)."""
    placeholders = {n: i for i, n in enumerate(n for n in gm.graph.nodes if n.op == "placeholder")}
    for node in gm.graph.nodes:
        if node.op != "call_function" or not getattr(node.target, "_schema", None) or not node.target._schema.is_mutable:
            continue
        base = node.args[0]
        while getattr(base, "op", None) == "call_function" and base.target._schema.returns and \
                base.target._schema.returns[0].alias_info is not None:  # through views to their base
            base = base.args[0]
        if base in placeholders:
            raise TypeError(f"{name} writes into {arg_names[placeholders[base]]} in place ({node.target}); the "
                            "compiled step math must assign new tensors instead")


class _Graph:
    """One traced and compiled specialisation of a :class:`GraphMethod`."""

    __slots__ = ("inputs", "guard", "compiled", "writes", "unflatten", "consts")

    def __init__(self, inputs, guard, compiled, writes, out_spec, consts):
        self.inputs = inputs      # [(attribute, kind)]: 0 a tensor, 1 a Relational, 2 a tuple of tensors, 3 another pytree
        self.guard = guard
        self.compiled = compiled
        self.writes = writes      # attributes the method assigns, in the order of its outputs
        self.unflatten = _unflattener(out_spec)  # leaves -> (return value, [written attribute values])
        # non-tensor leaves of the outputs by position (None where a graph output goes), or None if none
        self.consts = consts if any(c is not None for c in consts) else None

    def gather(self, owner_dict: dict, args) -> list:
        flat = [a for a in args if a is not None]
        for name, kind in self.inputs:
            v = owner_dict[name]
            if kind == 0:
                flat.append(v)
            elif kind == 1:
                flat.append(v.data)
            elif kind == 2:
                flat.extend(v)
            else:
                flat.extend(pytree.tree_leaves(v))
        return flat

    def run(self, owner_dict: dict, flat: list):
        outs = self.compiled(*flat)
        if self.consts is not None:
            it = iter(outs)
            outs = [next(it) if c is None else c[0] for c in self.consts]
        ret, written = self.unflatten(outs)
        for name, v in zip(self.writes, written):
            owner_dict[name] = v
        return ret


# graphs shared by the tasks of a process whose ``_graph_context()`` is equal (evaluation makes one
# task per object and axis): {(module, method, context): {(key, argument pattern): [_Graph]}}
_SHARED: dict = {}


class GraphMethod:
    """``method(owner, *args)`` compiled as one graph of its tensor arguments and ``owner``'s tensor
    state (CPU): what ``torch.compile`` does for the step math, without Dynamo's per-call cost.

    At the first call (and for every new specialisation) the method is traced with ``make_fx`` as a
    pure function: (arguments, every tensor-valued attribute of ``owner``) -> (return value, every
    attribute it assigns); attributes the graph does not read are dropped from its inputs. Inductor
    compiles the graph (its on-disk FX graph cache serves later processes). A call gathers the
    inputs, checks their shapes, strides and dtypes against the graph's (one C++ check; a mismatch
    traces a new specialisation), runs the graph and writes the assigned attributes back.

    What the trace bakes in (Dynamo's guards checked these at every call): every Python value the
    method reads (configuration, reward terms, hand constants, tensors inside other Python objects).
    They must stay fixed for the life of ``owner``, except the ones ``owner._graph_key()`` returns
    (optional; a hashable of the values that may change after construction, e.g. at scene
    rebuilds), which select the specialisation. Calls with a ``None`` argument and with a tensor
    there are separate specialisations. After ``limit`` specialisations the method runs eagerly
    (said once).

    Owners with an equal ``owner._graph_context()`` (optional; a string naming everything fixed at
    construction that the trace may bake in: class, configuration, hand, ...) share their graphs
    within the process, so a new task costs no trace. The first call of each owner on a graph it
    did not trace also runs the method eagerly and compares (1e-4): a context that misses a value
    the graph baked in raises instead of computing something else."""

    def __init__(self, owner, fn: Callable, limit: int = RECOMPILE_LIMIT):
        self._owner = weakref.ref(owner)  # the task holds this object: no reference cycle
        self._fn = getattr(fn, "__func__", fn)  # the plain function of a bound method
        self.__name__ = getattr(self._fn, "__name__", "method")
        self._graphs = None   # this owner's {(key, argument pattern): [_Graph]}, shared when it has a context
        self._context = None
        self._checked = set()  # ids of shared graphs this owner has compared with the eager method
        self._count = 0
        self._limit = limit
        self._eager = False

    def _table(self, owner) -> dict:
        ctx_fn = getattr(owner, "_graph_context", None)
        if ctx_fn is None:
            return {}
        self._context = (self._fn.__module__, self._fn.__qualname__, ctx_fn())
        return _SHARED.setdefault(self._context, {})

    def __call__(self, *args):
        owner = self._owner()
        if self._eager:
            return self._fn(owner, *args)
        if self._graphs is None:
            self._graphs = self._table(owner)
        d = owner.__dict__
        key_fn = getattr(owner, "_graph_key", None)
        key = (key_fn() if key_fn is not None else None, tuple(a is None for a in args))
        graphs = self._graphs.setdefault(key, [])
        for g in graphs:
            flat = g.gather(d, args)
            if g.guard(flat):
                if self._context is not None and id(g) not in self._checked:
                    return self._run_checked(owner, g, args, flat)
                return g.run(d, flat)
        if len(graphs) >= self._limit:
            self._eager = True
            print(f"[unicross] {self.__name__}: {self._limit} compiled specialisations; running it eagerly from "
                  "now on", file=sys.stderr, flush=True)
            return self._fn(owner, *args)
        announce = self._count == 0 and _announce_start()
        t = time.perf_counter()
        try:
            g = self._build(owner, args)
        except Exception as e:  # the trace and the C++ build are optional: eager is always right
            if not _is_backend_error(e):
                raise
            self._eager = True
            _fall_back(e)
            return self._fn(owner, *args)
        self._count += 1
        self._checked.add(id(g))
        graphs.append(g)
        if announce:
            print(f"[unicross] step math compiled in {time.perf_counter() - t:.1f} s (pid {os.getpid()})",
                  file=sys.stderr, flush=True)
        return g.run(d, g.gather(d, args))

    def _run_checked(self, owner, g: _Graph, args, flat):
        """The first call of this owner on a graph another owner traced: the eager method on the same
        state must agree (then the graph's result and writes are kept)."""
        d = owner.__dict__
        saved = dict(d)
        want = self._fn(owner, *args)
        want_state = {n: d.get(n) for n in g.writes}
        d.clear()
        d.update(saved)
        got = g.run(d, flat)
        try:
            tensors = [[x for x in pytree.tree_leaves(v) if torch.is_tensor(x)]
                       for v in ((got, [d[n] for n in g.writes]), (want, [want_state[n] for n in g.writes]))]
            torch.testing.assert_close(tensors[0], tensors[1], rtol=1e-4, atol=1e-4, equal_nan=True)
        except AssertionError as e:
            raise RuntimeError(f"{self.__name__}: the compiled graph shared by tasks with the same _graph_context() "
                               f"disagrees with the eager method for {type(owner).__name__}: the context misses a "
                               f"value the graph depends on.\n{e}") from None
        self._checked.add(id(g))
        return got

    def _build(self, owner, args) -> _Graph:
        from torch.fx.experimental.proxy_tensor import make_fx
        from torch._inductor import config as inductor_config
        from torch._inductor.compile_fx import compile_fx

        settle_vec_isa()
        d = owner.__dict__
        names = [n for n, v in d.items() if _is_state(v)]
        specs = [pytree.tree_flatten(d[n]) for n in names]
        arg_tensors = [a for a in args if a is not None]
        example = arg_tensors + [x for leaves, _ in specs for x in leaves]
        fn, record = self._fn, {}

        def pure(*flat):
            it = iter(flat)
            call_args = [None if a is None else next(it) for a in args]
            saved = dict(d)
            installed = {}
            for n, (leaves, spec) in zip(names, specs):
                installed[n] = d[n] = pytree.tree_unflatten([next(it) for _ in leaves], spec)
            try:
                ret = fn(owner, *call_args)
                writes = [n for n, v in d.items() if v is not installed.get(n, saved.get(n, _MISSING))]
                bad = [n for n in writes if not _is_state(d[n])]
                if bad:
                    raise TypeError(f"{self.__name__} assigns non-tensor attributes {bad}: the compiled step math "
                                    "may only assign tensors (or tuples/dicts of them) to the task")
                written = [d[n] for n in writes]
            finally:
                d.clear()
                d.update(saved)
            leaves, spec = pytree.tree_flatten((ret, written))
            for x in leaves:
                if not torch.is_tensor(x) and x is not None and not isinstance(x, (bool, int, float, str)):
                    raise TypeError(f"{self.__name__} returns a {type(x).__name__}: only tensors and constants")
            record.update(writes=writes, spec=spec,
                          consts=[None if torch.is_tensor(x) else (x,) for x in leaves])
            return [x for x in leaves if torch.is_tensor(x)]

        gm = make_fx(pure, tracing_mode="fake", _allow_non_fake_inputs=True)(*example)
        _refuse_input_writes(gm, self.__name__, arg_names=[f"argument {k}" for k in range(len(arg_tensors))] +
                             [n for n, (leaves, _) in zip(names, specs) for _ in leaves])
        # drop the inputs of attributes the graph does not read
        placeholders = [n for n in gm.graph.nodes if n.op == "placeholder"]
        keep_inputs, keep_example, pos = [], list(arg_tensors), len(arg_tensors)
        for name, (leaves, _) in zip(names, specs):
            nodes = placeholders[pos:pos + len(leaves)]
            if any(node.users for node in nodes):
                keep_inputs.append((name, _kind(d[name])))
                keep_example.extend(example[pos:pos + len(leaves)])
            else:
                for node in nodes:
                    gm.graph.erase_node(node)
            pos += len(leaves)
        gm.graph.lint()
        gm.recompile()
        with inductor_config.patch(CPU_OPTIONS), _inner_graphs() as inner:
            compiled = compile_fx(gm, keep_example, inner_compile=inner.compile)
        compiled = _direct(compiled, inner.seen, [*gm.parameters(), *gm.buffers()], keep_example)
        return _Graph(keep_inputs, _InputGuard(keep_example), compiled, record["writes"], record["spec"],
                      record["consts"])


_MISSING = object()


class _inner_graphs:
    """Records the Inductor graphs ``compile_fx`` makes or loads, with the number of inputs each takes:
    ``seen`` = [(CompiledFxGraph, inputs)]. A fresh compile goes through ``compile`` (its ``inner_compile``),
    which counts the graph's placeholders. A hit in AOTAutograd's cache skips that and loads the graph
    from Inductor's cache (``_load_and_post_compile``, patched for the duration); the graph then takes
    AOTAutograd's flat inputs one for one provided no tensor appears twice among them (AOTAutograd
    would pass the duplicate once), so only then is it recorded."""

    def __init__(self):
        self.seen = []
        self._patched = None

    def compile(self, graph, example_inputs, **kw):
        from torch._inductor.compile_fx import compile_fx_inner
        out = compile_fx_inner(graph, example_inputs, **kw)
        self.seen.append((out, sum(1 for n in graph.graph.nodes if n.op == "placeholder")))
        return out

    def __enter__(self):
        try:
            from torch._functorch._aot_autograd.aot_autograd_result import GenericAOTAutogradResult as R
            load = R._load_and_post_compile
        except (ImportError, AttributeError):  # another torch: cache hits run wrapped
            return self
        seen = self.seen

        def recording(entry, args, fx_config):
            fw, bw, needs_autograd = load(entry, args, fx_config)
            if bw is None and len({id(a) for a in args}) == len(args):
                seen.append((fw, len(args)))
            else:
                seen.append((None, -1))
            return fw, bw, needs_autograd

        R._load_and_post_compile, self._patched = recording, (R, load)
        return self

    def __exit__(self, *exc):
        if self._patched is not None:
            R, load = self._patched
            R._load_and_post_compile = load


def _direct(wrapped: Callable, inner: list, lifted: list, example: list) -> Callable:
    """Inductor's compiled graph called directly (``current_callable`` on a list of the inputs), without
    AOTAutograd's runtime wrappers and ``CompiledFxGraph.__call__``'s per-call bookkeeping (1-5% of a
    whole task step on the CPU, measured in one process), when that is the same function: one inner
    graph whose inputs are the graph module's ``lifted`` parameters and buffers (AOTAutograd passes them
    first) and then exactly the inputs given, and which returns the wrapped call's outputs, bit for bit
    and with the same layout, on the example inputs. Otherwise ``wrapped``."""
    if len(inner) != 1:
        return wrapped
    out, n_inputs = inner[0]
    call = getattr(out, "current_callable", None)
    if call is None or n_inputs != len(lifted) + len(example):
        return wrapped
    lifted = [t.detach() for t in lifted]
    want, got = wrapped(*example), call([*lifted, *example])
    if not isinstance(got, (list, tuple)) or len(got) != len(want) or not all(
            torch.is_tensor(a) and torch.is_tensor(b) and a.shape == b.shape and a.dtype == b.dtype
            and a.stride() == b.stride() and torch.equal(a, b) for a, b in zip(want, got)):
        return wrapped

    def direct(*flat):
        return call([*lifted, *flat])
    return direct


def _kind(v) -> int:
    """How :meth:`_Graph.gather` takes an attribute's tensors: 0 a tensor, 1 a pytree node with one
    ``data`` leaf (``formulation.Relational``), 2 a tuple of tensors, 3 any other pytree."""
    if torch.is_tensor(v):
        return 0
    if torch.is_tensor(getattr(v, "data", None)) and pytree.tree_leaves(v) == [v.data]:
        return 1
    if type(v) is tuple and all(torch.is_tensor(x) for x in v):
        return 2
    return 3


def _is_backend_error(e: Exception) -> bool:
    """Errors of the C++ build (no compiler, a failed compile), not of the traced math."""
    mod = type(e).__module__ or ""
    return mod.startswith(("torch._inductor", "torch._dynamo", "subprocess")) or isinstance(e, (OSError,))


def compile_method(owner, fn: Callable, cpu: bool = True, enabled: Optional[bool] = None) -> Callable:
    """The step math ``fn`` (a method of ``owner``) as ``enabled`` (None: the ``UNICROSS_COMPILE``
    switch) says: eager when off; else a :class:`GraphMethod` on the CPU and ``torch.compile``
    (:func:`maybe_compile`) on the GPU or with ``UNICROSS_COMPILE=torch``."""
    if not (compile_enabled() if enabled is None else enabled):
        return fn
    return GraphMethod(owner, fn) if cpu and not compile_with_dynamo() else maybe_compile(fn, cpu=cpu)
