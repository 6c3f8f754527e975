"""Closest points on the exact object geometry agree with trimesh's closest-point query."""
import numpy as np
import pytest
import torch
import trimesh

from unicross.geometry import closest_point_shapes, quat_angle, quat_from_euler_xyz, quat_to_euler_xyz, slerp_toward
from unicross.objects import ObjectSpec, get_object_set

pytestmark = pytest.mark.unit

TOL = 1e-3  # 1 mm


def _query_points(spec, n=400, seed=0):
    rng = np.random.default_rng(seed)
    ext = np.asarray(spec.trimesh().bounding_box.extents)
    # points inside, near and outside the surface, as links see them
    return (rng.uniform(-1, 1, size=(n, 3)) * (ext / 2 + 0.04)).astype(np.float32)


def _check(spec, tris=None):
    pts = _query_points(spec)
    mesh = spec.trimesh()
    ref, _, _ = trimesh.proximity.closest_point(mesh, pts)
    st = torch.tensor([spec.shape_type])
    params = torch.tensor(spec.params)[None]
    out = closest_point_shapes(torch.from_numpy(pts)[None], st, params, tris)[0].numpy()
    # compare distances (the closest point may be non-unique on symmetric shapes) and points
    d_ref = np.linalg.norm(ref - pts, axis=1)
    d_out = np.linalg.norm(out - pts, axis=1)
    assert np.abs(d_ref - d_out).max() < TOL
    # the returned point lies on the surface
    on, dist_surf, _ = trimesh.proximity.closest_point(mesh, out)
    assert dist_surf.max() < TOL
    close = np.linalg.norm(ref - out, axis=1) < TOL
    assert close.mean() > 0.95  # differs only where two surface points are equally near


@pytest.mark.parametrize("set_name", ["train-wrappable", "train-elongated", "unseen-wrappable", "unseen-elongated"])
def test_primitives_match_trimesh(set_name):
    objs = get_object_set(set_name, limit=2)
    assert {o.shape for o in objs} >= ({"box", "cylinder"} if "train" in set_name else {"prism"})
    for spec in objs:
        _check(spec)


def test_user_mesh_matches_trimesh(tmp_path):
    # a non-convex mesh: a torus
    m = trimesh.creation.torus(major_radius=0.03, minor_radius=0.01, major_sections=24, minor_sections=12)
    path = tmp_path / "torus.obj"
    m.export(path)
    spec = get_object_set(f"mesh:{path}")[0]
    mesh = spec.trimesh()
    tris = torch.tensor(np.asarray(mesh.triangles), dtype=torch.float32)[None]
    _check(spec, tris)


def test_sphere_shape_sets_distance():
    spec = ObjectSpec("s", "sphere", "wrappable", (0.06,))
    p = torch.tensor([[[0.1, 0.0, 0.0], [0.0, 0.01, 0.0]]])
    out = closest_point_shapes(p, torch.tensor([spec.shape_type]), torch.tensor(spec.params)[None])
    assert torch.allclose(out[0, 0], torch.tensor([0.03, 0.0, 0.0]), atol=1e-6)
    assert torch.allclose(out[0, 1], torch.tensor([0.0, 0.03, 0.0]), atol=1e-6)


def test_euler_roundtrip_and_slerp():
    e = torch.tensor([[0.3, -0.5, 1.2], [0.0, 0.0, 0.0]])
    q = quat_from_euler_xyz(e)
    assert torch.allclose(quat_to_euler_xyz(q), e, atol=1e-5)
    q2 = slerp_toward(q[1:], q[:1], 0.1)
    assert torch.allclose(quat_angle(q[1:], q2), torch.tensor([0.1]), atol=1e-5)


def test_lean_quaternion_ops_match_reference():
    from mani_skill.utils.geometry import rotation_conversions as rc
    from unicross.geometry import quat_apply, quat_from_axis_angle, quat_inv, quat_mul, quat_to_axis_angle
    g = torch.Generator().manual_seed(0)
    q1 = torch.randn(64, 4, generator=g)
    q1 = q1 / q1.norm(dim=-1, keepdim=True)
    q2 = torch.randn(64, 4, generator=g)
    q2 = q2 / q2.norm(dim=-1, keepdim=True)
    v = torch.randn(64, 3, generator=g)
    assert torch.allclose(quat_mul(q1, q2), rc.quaternion_raw_multiply(q1, q2), atol=1e-6)
    assert torch.allclose(quat_apply(q1, v), rc.quaternion_apply(q1, v), atol=1e-5)
    assert torch.allclose(quat_mul(q1, quat_inv(q1))[:, 0], torch.ones(64), atol=1e-6)
    rv = rc.quaternion_to_axis_angle(rc.standardize_quaternion(q1))
    assert torch.allclose(quat_to_axis_angle(q1), rv, atol=1e-4)
    axis = torch.nn.functional.normalize(torch.randn(64, 3, generator=g), dim=-1)
    ang = torch.rand(64, generator=g) * 3
    assert torch.allclose(quat_from_axis_angle(axis, ang), rc.axis_angle_to_quaternion(axis * ang[:, None]), atol=1e-6)
    assert torch.allclose(quat_angle(q1, quat_mul(quat_from_axis_angle(axis, ang), q1)), ang, atol=1e-4)
