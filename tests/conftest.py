import os

import pytest

os.environ.setdefault("UNICROSS_CACHE", os.path.join(os.path.dirname(__file__), "..", ".cache-tests"))
# the suite runs the step math eagerly (a cold torch.compile costs ~1 min per process);
# tests/test_compile.py compiles it explicitly and checks the two agree
os.environ.setdefault("UNICROSS_COMPILE", "0")


@pytest.fixture(autouse=True)
def _unit_tests_build_no_simulator(request, monkeypatch):
    """Tests marked ``unit`` must not make an environment (the unit tier runs without SAPIEN)."""
    if request.node.get_closest_marker("unit"):
        import gymnasium

        def refuse(*args, **kwargs):
            raise AssertionError("a test marked unit made an environment")
        monkeypatch.setattr(gymnasium, "make", refuse)


@pytest.fixture(scope="session")
def tiny_objects():
    from unicross.objects import get_object_set
    return get_object_set("train", limit=1)  # 1 box + 1 cylinder per category


@pytest.fixture(scope="session")
def grasp_file(tmp_path_factory, tiny_objects):
    """A real grasp dataset for the tiny object set, made by the scripted synthesiser."""
    from unicross.scripted_grasp import synthesize
    gs, stats = synthesize("allegro", tiny_objects, per_object=2, seed=0, progress=False)
    path = tmp_path_factory.mktemp("grasps") / "tiny.pt"
    gs.save(path)
    return str(path)


def make(task, grasp_file=None, **kw):
    import gymnasium as gym
    import unicross  # noqa: F401
    args = dict(obs_mode="state", sim_backend="physx_cpu", render_backend="none", object_limit=1)
    if grasp_file is not None and task != "UniCross-Grasp-v1":
        args["grasp_dataset"] = grasp_file
    args.update(kw)
    return gym.make(task, **args)
