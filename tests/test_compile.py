"""The compiled step math (UNICROSS_COMPILE) computes what the eager math computes."""
import pytest
import torch

from conftest import make
from unicross.compiling import GraphMethod, compile_enabled, maybe_compile

IDS = [("UniCross-Grasp-v1", {}), ("UniCross-Relocate-v1", {}), ("UniCross-Rotate-v1", {"axis": "x-"}),
       ("UniCross-Translate-v1", {"direction": "z+"}), ("UniCross-MultiSkill-v1", {})]


def test_switch(monkeypatch):
    def f(x):
        return x + 1
    monkeypatch.setenv("UNICROSS_COMPILE", "0")
    assert not compile_enabled() and maybe_compile(f) is f
    monkeypatch.setenv("UNICROSS_COMPILE", "1")
    g = maybe_compile(f)
    assert compile_enabled() and g is not f
    x = torch.arange(3.0)
    assert torch.equal(g(x), x + 1) and torch.equal(g(x), x + 1)


def test_an_env_can_opt_out_of_the_switch(monkeypatch, grasp_file):
    """``compile_math=False`` keeps an env's step math eager with the switch on (the SAPIEN
    renderer's replay env only resets: compiling there cost a minute on a lent machine), and
    ``compile_math=True`` compiles it with the switch off."""
    monkeypatch.setenv("UNICROSS_COMPILE", "1")
    u = make("UniCross-Grasp-v1", grasp_file, compile_math=False).unwrapped
    assert not u._compiled and not isinstance(u._step_math, GraphMethod)
    assert u._step_math == u._step_math_eager and u._command_math == u._command_math_eager
    monkeypatch.setenv("UNICROSS_COMPILE", "0")
    u = make("UniCross-Grasp-v1", grasp_file, compile_math=True).unwrapped
    assert u._compiled and isinstance(u._step_math, GraphMethod) and isinstance(u._command_math, GraphMethod)
    u = make("UniCross-Grasp-v1", grasp_file).unwrapped
    assert not u._compiled and u._step_math == u._step_math_eager


def _compare(task, kw, grasp_file):
    """Step a few times with random actions, then run one step's math eagerly and compiled
    (:class:`GraphMethod`, what ``UNICROSS_COMPILE=1`` runs on the CPU) from the same reads and the
    same task state: every info value and every state tensor it writes agree
    (the compiled run also evaluates every primitive's closest-point formula, as it does when
    UNICROSS_COMPILE is on, while the eager run evaluates only the object's own)."""
    env = make(task, grasp_file, **kw)
    u = env.unwrapped
    u.reset(seed=1)
    g = torch.Generator().manual_seed(0)
    for _ in range(3):
        u.step((torch.rand(1, u.hand_spec.dof, generator=g) * 2 - 1) * 0.5)
    # the action -> joint command math
    a = (torch.rand(1, u.hand_spec.dof, generator=g) * 2 - 1) * 0.5
    draws = u._draw_perturbation()
    assert draws[0] is not None  # randomisation on: the perturbation forces are part of the math
    saved = dict(vars(u))
    (eager_targets, eager_forces), eager_command, eager_perturb = u._command_math_eager(a, u.elapsed_steps, *draws), \
        u.command, u.perturb
    vars(u).update(saved)
    targets, forces = GraphMethod(u, type(u)._command_math_eager)(a, u.elapsed_steps, *draws)
    torch.testing.assert_close(targets, eager_targets, atol=1e-5, rtol=1e-5)
    torch.testing.assert_close(forces, eager_forces, atol=1e-5, rtol=1e-5)
    assert float(forces.abs().max()) > 0
    torch.testing.assert_close(u.command, eager_command, atol=1e-5, rtol=1e-5)
    torch.testing.assert_close(u.perturb, eager_perturb, atol=1e-5, rtol=1e-5)
    vars(u).update(saved)
    # the math after the reads
    u._pending = torch.ones_like(u._pending)  # as right after a physics step
    reads = u._read()
    noise = torch.rand(u.obs_noise.shape, generator=g) * 0.02
    saved = dict(vars(u))
    eager_info, eager_out = u._step_math_eager(*reads, u.elapsed_steps, noise)
    eager_state = dict(vars(u))
    vars(u).update(saved)
    u._closest_kinds = frozenset(range(4))  # as when compiling: every primitive's formula, selected per env
    gm = GraphMethod(u, type(u)._step_math_eager)
    info, out = gm(*reads, u.elapsed_steps, noise)
    assert info.keys() == eager_info.keys()
    assert [g.compiled.__name__ for gs in gm._graphs.values() for g in gs] == ["direct"]  # without AOT's wrappers
    for name, got, want in zip(("obs", "reward", "terminated", "truncated"), out, eager_out):
        torch.testing.assert_close(got, want, atol=1e-5, rtol=1e-5, msg=lambda m: f"{task} {name}: {m}")
    for k, v in eager_info.items():
        torch.testing.assert_close(info[k], v, atol=1e-5, rtol=1e-5, msg=lambda m: f"{task} info[{k}]: {m}")
    state = dict(vars(u))
    assert {k for k, v in eager_state.items() if v is not saved.get(k)} == \
        {k for k, v in state.items() if v is not saved.get(k)} - {"_closest_kinds"}  # the same attributes written
    for k, v in eager_state.items():
        got = state[k]
        if hasattr(v, "data") and not torch.is_tensor(v):  # Relational
            v, got = v.data, got.data
        if torch.is_tensor(v) and got is not saved.get(k):
            torch.testing.assert_close(got, v, atol=1e-5, rtol=1e-5, msg=lambda m: f"{task} {k}: {m}")
    for k in ("distance", "force", "qpos", "contact", "goal"):
        torch.testing.assert_close(u._obs_parts[k], eager_state["_obs_parts"][k], atol=1e-5, rtol=1e-5)
    for k in ("vec", "force", "qpos", "contact"):
        torch.testing.assert_close(u._measured[k], eager_state["_measured"][k], atol=1e-5, rtol=1e-5)
    env.close()


def test_compiled_math_matches_eager(grasp_file):
    _compare("UniCross-Relocate-v1", {}, grasp_file)


@pytest.mark.slow
@pytest.mark.parametrize("task,kw", IDS, ids=[t for t, _ in IDS])
def test_compiled_math_matches_eager_every_id(task, kw, grasp_file):
    _compare(task, kw, grasp_file)


def test_falls_back_to_eager_without_a_compiler(monkeypatch, tmp_path, capsys):
    """A machine without a working C++ compiler still steps: the compile error is reported once
    and the math runs eagerly."""
    import torch._inductor.config as inductor_config
    monkeypatch.setenv("UNICROSS_COMPILE", "1")
    monkeypatch.setenv("TORCHINDUCTOR_CACHE_DIR", str(tmp_path))
    torch._dynamo.reset()

    def f(x):
        return (x * 3).cos() - 2

    g = maybe_compile(f)
    x = torch.arange(4.0)
    # torch's own patch: pytest >= 9.2's monkeypatch deletes the config entry at undo (SubConfigProxy
    # has no instance __dict__ entry), which hides cpp.cxx for the rest of the process
    with inductor_config.patch({"cpp.cxx": (None, "/bin/false")}):
        assert torch.equal(g(x), f(x)) and torch.equal(g(x), f(x))
    assert "compiling the step math failed" in capsys.readouterr().err
    torch._dynamo.reset()


class _Toy:
    """A task-like owner: tensor state, a Relational, a tuple of tensors, a Python setting and a
    ``_graph_key``."""

    def __init__(self, n=2):
        from unicross.formulation import Relational
        self.x = torch.arange(float(n))
        self.rel = Relational(torch.ones(n, 21))
        self.gains = (torch.tensor(2.0), torch.tensor(0.5))
        self.scale = 3.0        # fixed after construction: baked into the graph
        self.variant = "add"    # may change: named by _graph_key
        self.unused = torch.zeros(5)
        self.math = GraphMethod(self, _Toy.step)

    def _graph_key(self):
        return self.variant

    def step(self, a, extra=None):
        from unicross.formulation import Relational
        y = self.x * self.gains[0] + a if self.variant == "add" else self.x * a
        if extra is not None:
            y = y + extra
        self.x = y * self.scale
        self.rel = Relational(self.rel.data + y.sum())
        self.new = y.clone()  # an attribute the method creates
        return {"y": y, "n": self.x.shape[0]}, (y.sum(), None)


def _eager_twin(toy):
    twin = _Toy.__new__(_Toy)
    vars(twin).update({k: v for k, v in vars(toy).items() if k != "math"})
    return twin


def test_graph_method_matches_eager_and_writes_state():
    toy = _Toy()
    twin = _eager_twin(toy)
    for i in range(3):
        a = torch.full((2,), float(i))
        got = toy.math(a)
        want = _Toy.step(twin, a)
        assert got[0]["n"] == want[0]["n"] == 2 and got[1][1] is None
        torch.testing.assert_close(got[0]["y"], want[0]["y"])
        torch.testing.assert_close(got[1][0], want[1][0])
        for k in ("x", "new"):
            torch.testing.assert_close(getattr(toy, k), getattr(twin, k))
        torch.testing.assert_close(toy.rel.data, twin.rel.data)
        assert type(toy.rel).__name__ == "Relational"
    g = toy.math._graphs[("add", (False,))][0]
    assert "unused" not in [n for n, _ in g.inputs] and "x" in [n for n, _ in g.inputs]
    assert g.compiled.__name__ == "direct"  # Inductor's graph without AOTAutograd's wrappers
    assert toy.math._count == 1  # one trace for three calls


def test_direct_call_only_where_it_is_the_same_function():
    from unicross.compiling import _direct

    class Inner:
        def __init__(self, fn):
            self.current_callable = fn

    x = torch.arange(3.0)
    wrapped = lambda t: [t * 2.0, t + 1.0]  # noqa: E731
    same = Inner(lambda ins: [ins[1] * 2.0, ins[1] + 1.0])  # one lifted constant first, then the input
    assert _direct(wrapped, [(same, 2)], [torch.zeros(1)], [x]).__name__ == "direct"
    assert _direct(wrapped, [(same, 2)], [torch.zeros(1)], [x])(x)[1].tolist() == [1.0, 2.0, 3.0]
    assert _direct(wrapped, [], [], [x]) is wrapped                                      # no inner graph seen
    assert _direct(wrapped, [(same, 2), (same, 2)], [torch.zeros(1)], [x]) is wrapped    # two graphs
    assert _direct(wrapped, [(same, 3)], [torch.zeros(1)], [x]) is wrapped               # other inputs
    other = Inner(lambda ins: [ins[1] * 2.0, ins[1] + 2.0])
    assert _direct(wrapped, [(other, 2)], [torch.zeros(1)], [x]) is wrapped              # other outputs
    layout = Inner(lambda ins: [ins[1] * 2.0, (ins[1] + 1.0).view(3, 1)])
    assert _direct(wrapped, [(layout, 2)], [torch.zeros(1)], [x]) is wrapped             # another layout


def test_graph_method_specialises_on_shapes_keys_and_missing_arguments():
    toy = _Toy()
    twin = _eager_twin(toy)

    def both(*args):
        got, want = toy.math(*args), _Toy.step(twin, *args)
        torch.testing.assert_close(got[0]["y"], want[0]["y"])
        torch.testing.assert_close(toy.x, twin.x)

    both(torch.ones(2))
    both(torch.ones(2), torch.ones(2))           # an argument given where it was None
    assert toy.math._count == 2
    toy.variant = twin.variant = "mul"           # a Python value named by _graph_key
    both(torch.ones(2))
    assert toy.math._count == 3
    for t in (toy, twin):                        # new shapes: a new specialisation, not a wrong result
        t.x, t.new = torch.arange(4.0), torch.zeros(4)
        t.rel = type(t.rel)(torch.ones(4, 21))
    both(torch.ones(4))
    assert toy.math._count == 4
    toy.x, twin.x = toy.x.double(), twin.x.double()  # a new dtype too
    both(torch.ones(4, dtype=torch.float64))
    assert toy.math._count == 5
    toy.x = twin.x = torch.arange(8.0).view(4, 2)[:, 0]  # a strided view
    both(torch.ones(4))
    assert toy.math._count == 6
    toy.x = twin.x = toy.x.contiguous()
    a = toy.x                                    # an argument that is also state: no new trace
    both(a.clone())
    count = toy.math._count
    both(toy.x)
    assert toy.math._count == count


def test_graph_method_refuses_writes_into_inputs_and_non_tensor_state():
    class InPlace(_Toy):
        def step(self, a, extra=None):
            self.x[0] = a[0]
            return self.x.sum()

    class Flag(_Toy):
        def step(self, a, extra=None):
            self.flag = True
            return self.x + a

    with pytest.raises(TypeError, match="writes into x in place"):
        t = InPlace()
        GraphMethod(t, InPlace.step)(torch.ones(2))
    with pytest.raises(TypeError, match="non-tensor attributes"):
        t = Flag()
        GraphMethod(t, Flag.step)(torch.ones(2))


def test_graph_method_falls_back_to_eager_without_a_compiler(monkeypatch, tmp_path, capsys):
    import torch._inductor.config as inductor_config
    monkeypatch.setenv("TORCHINDUCTOR_CACHE_DIR", str(tmp_path))
    toy = _Toy()
    twin = _eager_twin(toy)
    with inductor_config.patch({"cpp.cxx": (None, "/bin/false")}):  # not monkeypatch (see above)
        for _ in range(2):
            torch.testing.assert_close(toy.math(torch.ones(2))[0]["y"], _Toy.step(twin, torch.ones(2))[0]["y"])
    assert "failed" in capsys.readouterr().err and toy.math._eager


@pytest.mark.slow
def test_graph_method_follows_the_chain_like_torch_compile(monkeypatch):
    """The chain changes a Python value the step math reads (``static_skill``) at its phase switches.
    The compiled env follows it (``_graph_key``): step by step it gives what ``torch.compile`` gives
    (whose guards re-check every Python value at every call). Eager is no reference here: contact
    amplifies the ~1e-7 compiled-vs-eager differences to 1e-1 within a few steps of the grasp."""
    from unicross.scripted_grasp import ScriptedGrasp
    runs = {}
    for name, flag in (("torch.compile", "torch"), ("GraphMethod", "1")):
        monkeypatch.setenv("UNICROSS_COMPILE", flag)
        env = make("UniCross-Chain-v1", objects="test-wrappable", sequence="grasp,relocate,rotate:y-",
                   phase_steps=dict(grasp=60, relocate=10, rotate=10), randomize=False)
        u = env.unwrapped
        assert isinstance(u._step_math, GraphMethod) == (name == "GraphMethod")
        env.reset(seed=1)
        policy = ScriptedGrasp(u)
        rows = []
        for t in range(80):
            obs, reward, term, _, info = env.step(policy() if t < 55 else torch.zeros(1, 22))
            rows.append((obs, reward, u.mode.item(), u.static_skill))
            if term.any():
                break
        runs[name] = rows
        env.close()
    assert [r[2:] for r in runs["torch.compile"]] == [r[2:] for r in runs["GraphMethod"]]
    assert {r[3] for r in runs["GraphMethod"]} == {"grasp", "relocate", "rotate"}
    for (o0, r0, *_), (o1, r1, *_) in zip(runs["torch.compile"], runs["GraphMethod"]):
        torch.testing.assert_close(o1, o0, atol=1e-6, rtol=1e-6)
        torch.testing.assert_close(r1, r0, atol=1e-6, rtol=1e-6)


def test_graph_method_shares_graphs_between_owners_with_one_context():
    class Shared(_Toy):
        def _graph_context(self):
            return f"toy scale={self.scale}"

    class Forgetful(_Toy):  # a context that misses a value the graph bakes in
        def _graph_context(self):
            return "toy, scale left out"

    a, b = Shared(), Shared()
    twin = _eager_twin(b)
    a.math(torch.ones(2))
    got = b.math(torch.ones(2))                  # b's first call: a's graph, checked against eager
    torch.testing.assert_close(got[0]["y"], _Toy.step(twin, torch.ones(2))[0]["y"])
    assert (a.math._count, b.math._count) == (1, 0)
    c = Shared()
    c.scale = 5.0                                # another context: its own graph
    c.math(torch.ones(2))
    assert c.math._count == 1
    f1, f2 = Forgetful(), Forgetful()
    f2.scale = 7.0
    f1.math(torch.ones(2))
    with pytest.raises(RuntimeError, match="misses a value"):
        f2.math(torch.ones(2))


def test_tracing_leaves_no_fake_constants_behind():
    """Geometry caches its constants per device and dtype; a trace (fake tensors) must not fill that
    cache, or the next eager call would compute with fake tensors."""
    from unicross import geometry as G

    class Q:
        def __init__(self):
            self.q = torch.tensor([[0.6, 0.8, 0.0, 0.0]], dtype=torch.float64)
            self.math = GraphMethod(self, Q.step)

        def step(self, r):
            self.q = G.quat_mul(self.q, r)
            return self.q

    G._CACHE.clear()
    r = torch.tensor([[0.0, 0.0, 1.0, 0.0]], dtype=torch.float64)
    owner = Q()
    got = owner.math(r)
    assert all(type(c) is torch.Tensor for c in G._CACHE.values())
    torch.testing.assert_close(got, G.quat_mul(torch.tensor([[0.6, 0.8, 0.0, 0.0]], dtype=torch.float64), r))


@pytest.mark.skipif(__import__("platform").machine() not in ("x86_64", "AMD64"), reason="x86 probes")
def test_instruction_set_probes_run_once_per_machine(monkeypatch, tmp_path):
    """Inductor's SIMD probes (a child Python per instruction set, ~8 s each on the lent machines with
    torch 2.11) run in the first process only: it records their outcome in the cache directory, a
    later process reads it and sets ``cpp.vec_isa_ok`` without probing, and a record where a probe
    failed leaves Inductor to probe as before."""
    import json
    import unicross.compiling as c
    from torch._inductor import config as ic
    from torch._inductor import cpu_vec_isa as isa
    monkeypatch.setattr(c, "_records_dir", lambda: tmp_path)  # Inductor's own cache as it is
    real, probes = isa.valid_vec_isa_list, []
    monkeypatch.setattr(isa, "valid_vec_isa_list", lambda: probes.append(1) or real())
    try:
        with ic.patch({"cpp.vec_isa_ok": None}):
            c.settle_vec_isa.cache_clear()
            skipped = c.settle_vec_isa()
            (record,) = tmp_path.glob("unicross_vec_isa_*.json")
            rec = json.loads(record.read_text())
            assert probes == [1] and skipped == (rec["passed"] == rec["claimed"]) and rec["claimed"]
            assert ic.cpp.vec_isa_ok is (True if skipped else None)
        if not skipped:
            pytest.skip(f"a probe failed on this machine ({rec}): nothing to skip")
        monkeypatch.setattr(isa, "valid_vec_isa_list", lambda: pytest.fail("probed again"))
        with ic.patch({"cpp.vec_isa_ok": None}):  # a later process
            c.settle_vec_isa.cache_clear()
            assert c.settle_vec_isa() and ic.cpp.vec_isa_ok is True
            uncached = getattr(real, "__wrapped__", real)  # the same sets as the probes found
            assert [str(v) for v in uncached()] == rec["passed"]
        record.write_text(json.dumps(dict(rec, passed=rec["claimed"][1:])))  # a set the compiler failed
        with ic.patch({"cpp.vec_isa_ok": None}):
            c.settle_vec_isa.cache_clear()
            assert not c.settle_vec_isa() and ic.cpp.vec_isa_ok is None
    finally:
        c.settle_vec_isa.cache_clear()


@pytest.mark.skipif(__import__("platform").machine() not in ("x86_64", "AMD64"), reason="x86 probes")
def test_instruction_set_builds_are_remembered_per_machine(monkeypatch, tmp_path):
    """The sets' extra probes (``VecISA.check_build``: a test library built and loaded in a child
    Python) run once per machine: a success leaves a marker that a later call answers from, for the
    same set, flags and code only; a failure leaves none."""
    import unicross.compiling as c
    from torch._inductor import cpu_vec_isa as isa
    calls = []
    monkeypatch.setattr(isa.VecISA, "check_build", lambda self, code: calls.append(code) or "fail" not in code)
    c._remember_probe_builds(isa, tmp_path, ["torch", "python", "g++"])
    avx2, code = isa.VecAVX2(), isa.VecISA._avx_code
    assert avx2.check_build(code) and len(calls) == 1 and len(list(tmp_path.glob("unicross_isa_build_*.ok"))) == 1
    assert avx2.check_build(code) and len(calls) == 1  # remembered
    assert isa.VecAVX512().check_build(code) and len(calls) == 2  # another set's flags: probed
    assert not avx2.check_build(code + "fail") and not avx2.check_build(code + "fail") and len(calls) == 4
    c._remember_probe_builds(isa, tmp_path, ["torch", "python", "g++"])  # installed once
    assert avx2.check_build(code) and len(calls) == 4
