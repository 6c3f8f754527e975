"""Object sets and user meshes."""
import pytest
import torch
import trimesh

from conftest import make
from unicross.objects import (ELONGATED_LENGTH, ELONGATED_WIDTH, WRAPPABLE_RANGE, coacd_parts, get_object_set,
                              load_user_mesh)


def test_set_sizes_and_dimension_ranges():
    assert len(get_object_set("train")) == 400 and len(get_object_set("test")) == 400
    assert len(get_object_set("unseen")) == 400
    train = {o.name for o in get_object_set("train")}
    test = {o.name for o in get_object_set("test")}
    assert not train & test
    assert {o.dims for o in get_object_set("train")}.isdisjoint({o.dims for o in get_object_set("test")})
    for o in get_object_set("train-wrappable") + get_object_set("unseen-wrappable"):
        assert all(WRAPPABLE_RANGE[0] <= d <= WRAPPABLE_RANGE[1] for d in o.dims)
    for o in get_object_set("train-elongated") + get_object_set("unseen-elongated"):
        assert ELONGATED_LENGTH[0] <= o.dims[0] <= ELONGATED_LENGTH[1]
        assert all(ELONGATED_WIDTH[0] <= d <= ELONGATED_WIDTH[1] for d in o.dims[1:])
    shapes = {(o.shape, o.n_sides) for o in get_object_set("unseen")}
    assert shapes == {("sphere", 0), ("prism", 6), ("prism", 8)}
    assert get_object_set("train") == get_object_set("train")  # seeded
    with pytest.raises(ValueError, match="valid sets"):
        get_object_set("training")


def _torus(path):
    trimesh.creation.torus(major_radius=0.03, minor_radius=0.012).export(path)
    return path


def test_coacd_is_bounded_in_time_and_says_so(tmp_path, capsys):
    path = _torus(tmp_path / "torus_slow.obj")
    with pytest.raises(ValueError, match="did not finish"):
        coacd_parts(str(path), threshold=0.049, timeout=0.5)
    assert "CoACD: decomposing" in capsys.readouterr().err


def test_user_mesh_is_decomposed_cached_and_simulated(tmp_path):
    path = _torus(tmp_path / "torus.obj")
    parts = coacd_parts(str(path))
    assert len(parts) >= 2  # non-convex: several convex parts
    assert coacd_parts(str(path)) == parts  # cached
    env = make("UniCross-Grasp-v1", objects=f"mesh:{path}")
    obs, _ = env.reset(seed=0)
    for _ in range(3):
        obs, *_ = env.step(torch.zeros(22))
    assert torch.isfinite(obs).all()
    u = env.unwrapped
    d = u.get_obs(unflattened=True)["extra"]["object"]["distance"].view(-1, 3).norm(dim=-1)
    assert d.min() < 0.2
    env.close()


@pytest.mark.parametrize("content", ["not a mesh at all", ""])
def test_broken_mesh_fails_before_simulation(tmp_path, content):
    path = tmp_path / "broken.obj"
    path.write_text(content)
    with pytest.raises(ValueError):
        load_user_mesh(str(path))
    with pytest.raises(ValueError):
        make("UniCross-Grasp-v1", objects=f"mesh:{path}")
    with pytest.raises(ValueError, match="not found"):
        make("UniCross-Grasp-v1", objects=f"mesh:{tmp_path / 'missing.obj'}")


def test_a_large_user_mesh_is_simplified_before_coacd(capsys):
    from unicross.objects import simplified_for_coacd
    dense = trimesh.creation.icosphere(subdivisions=6, radius=0.03)  # 81,920 faces
    small = simplified_for_coacd(dense, "dense", max_faces=20000)
    assert len(small.faces) == 20000 and small.is_watertight
    assert "simplified from 81920 to 20000 faces" in capsys.readouterr().err
    assert simplified_for_coacd(small, "small", max_faces=20000) is small
