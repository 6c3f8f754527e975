"""The compiled step math (UNICROSS_COMPILE) computes what the eager math computes."""
import pytest
import torch

from conftest import make
from unicross.compiling import CPU_OPTIONS, compile_enabled, maybe_compile

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


def _compare(task, kw, grasp_file):
    """Step a few times with random actions, then run one step's math eagerly and compiled from the
    same reads and the same task state: every info value and every state tensor it writes agree
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
    targets, forces = torch.compile(u._command_math_eager, fullgraph=True, dynamic=False,
                                    options=CPU_OPTIONS)(a, u.elapsed_steps, *draws)
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
    compiled = torch.compile(u._step_math_eager, fullgraph=True, dynamic=False, options=CPU_OPTIONS)
    info, out = compiled(*reads, u.elapsed_steps, noise)
    assert info.keys() == eager_info.keys()
    for name, got, want in zip(("obs", "reward", "terminated", "truncated"), out, eager_out):
        torch.testing.assert_close(got, want, atol=1e-5, rtol=1e-5, msg=lambda m: f"{task} {name}: {m}")
    for k, v in eager_info.items():
        torch.testing.assert_close(info[k], v, atol=1e-5, rtol=1e-5, msg=lambda m: f"{task} info[{k}]: {m}")
    state = dict(vars(u))
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
    monkeypatch.setattr(inductor_config.cpp, "cxx", (None, "/bin/false"))
    torch._dynamo.reset()

    def f(x):
        return (x * 3).cos() - 2

    g = maybe_compile(f)
    x = torch.arange(4.0)
    assert torch.equal(g(x), f(x)) and torch.equal(g(x), f(x))
    assert "torch.compile failed" in capsys.readouterr().err
    torch._dynamo.reset()
