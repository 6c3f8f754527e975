"""Batched pose math and exact closest-point queries, in torch on any device.

Quaternions are ``(w, x, y, z)`` (SAPIEN's convention). Poses are ``(p, q)`` pairs of tensors
with a leading batch dimension. Everything here is vectorised: no Python loop over
environments.
"""
from __future__ import annotations

import math

import torch
from mani_skill.utils.geometry.rotation_conversions import (
    euler_angles_to_matrix,
    matrix_to_quaternion,
    quaternion_to_matrix,
)

__all__ = [
    "quat_mul", "quat_inv", "quat_apply", "quat_angle", "quat_from_euler_xyz", "quat_to_euler_xyz",
    "quat_from_axis_angle", "quat_to_axis_angle", "quat_to_matrix", "quat_from_matrix",
    "quat_positive", "pose_mul", "pose_inv", "relative_pose", "slerp_toward",
    "SHAPE_BOX", "SHAPE_CYLINDER", "SHAPE_SPHERE", "SHAPE_PRISM", "SHAPE_MESH",
    "closest_point_box", "closest_point_prism", "closest_point_sphere", "closest_point_triangles",
    "closest_point_shapes",
]

# Lean quaternion ops: few torch calls each (per-op dispatch dominates at small batch sizes).
_LMAT_IDX = torch.tensor([[0, 1, 2, 3], [1, 0, 3, 2], [2, 3, 0, 1], [3, 2, 1, 0]])
_LMAT_SIGN = torch.tensor([[1.0, -1.0, -1.0, -1.0], [1.0, 1.0, -1.0, 1.0], [1.0, 1.0, 1.0, -1.0], [1.0, -1.0, 1.0, 1.0]])
_CONJ = torch.tensor([1.0, -1.0, -1.0, -1.0])
_CACHE: dict = {}


def _const(t: torch.Tensor, like: torch.Tensor) -> torch.Tensor:
    """``t`` on ``like``'s device (and float dtype), cached per (constant, device, dtype) when eager;
    under torch.compile the conversion is traced into the graph instead (a lookup in the cache
    would become a guard evaluated in Python at every call), and while ``make_fx`` traces
    (``unicross.compiling.GraphMethod``: ``like`` is a fake tensor) it is not cached either."""
    dtype = like.dtype if t.is_floating_point() else t.dtype
    if torch.compiler.is_compiling() or type(like) is not torch.Tensor:
        return t.to(device=like.device, dtype=dtype)
    key = (id(t), like.device, like.dtype)
    c = _CACHE.get(key)
    if c is None:
        c = _CACHE[key] = t.to(device=like.device, dtype=dtype)
    return c


def quat_mul(q1: torch.Tensor, q2: torch.Tensor) -> torch.Tensor:
    """Hamilton product q1 ⊗ q2 (wxyz), as one matrix-vector product."""
    L = q1[..., _const(_LMAT_IDX, q1)] * _const(_LMAT_SIGN, q1)
    return (L @ q2.unsqueeze(-1)).squeeze(-1)


def quat_inv(q: torch.Tensor) -> torch.Tensor:
    """Inverse of a unit quaternion (its conjugate)."""
    return q * _const(_CONJ, q)


def quat_apply(q: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """Rotate vectors v [..., 3] by unit quaternions q [..., 4]."""
    u, w = q[..., 1:], q[..., :1]
    t = 2.0 * torch.linalg.cross(u, v, dim=-1)
    return v + w * t + torch.linalg.cross(u, t, dim=-1)


quat_to_matrix = quaternion_to_matrix


def quat_positive(q: torch.Tensor) -> torch.Tensor:
    """Canonical sign (w >= 0) so that q and -q map to the same numbers."""
    return q * torch.where(q[..., :1] < 0, -1.0, 1.0)


def quat_from_matrix(m: torch.Tensor) -> torch.Tensor:
    return quat_positive(matrix_to_quaternion(m))


def quat_from_euler_xyz(e: torch.Tensor) -> torch.Tensor:
    """Intrinsic XYZ Euler angles (Rx @ Ry @ Rz) -> quaternion; matches the virtual wrist chain."""
    return quat_from_matrix(euler_angles_to_matrix(e, "XYZ"))


def quat_to_euler_xyz(q: torch.Tensor) -> torch.Tensor:
    """Intrinsic XYZ Euler angles (a, b, c) with R = Rx(a) Ry(b) Rz(c), straight from the quaternion."""
    w, x, y, z = q.unbind(-1)
    r02 = 2 * (x * z + w * y)
    r12 = 2 * (y * z - w * x)
    r22 = 1 - 2 * (x * x + y * y)
    r01 = 2 * (x * y - w * z)
    r00 = 1 - 2 * (y * y + z * z)
    return torch.stack([torch.atan2(-r12, r22), torch.asin(r02.clamp(-1.0, 1.0)), torch.atan2(-r01, r00)], dim=-1)


def quat_from_axis_angle(axis: torch.Tensor, angle: torch.Tensor) -> torch.Tensor:
    """Rotation of ``angle`` (rad, shape [...]) about unit ``axis`` (shape [..., 3])."""
    half = 0.5 * angle.unsqueeze(-1)
    return torch.cat([torch.cos(half), axis * torch.sin(half)], dim=-1)


def quat_to_axis_angle(q: torch.Tensor) -> torch.Tensor:
    """Rotation vector (axis * angle, angle in [0, pi]) of a unit quaternion; robust near identity."""
    q = quat_positive(q)
    v, w = q[..., 1:], q[..., :1]
    s = torch.linalg.norm(v, dim=-1, keepdim=True)
    angle = 2.0 * torch.atan2(s, w)
    # angle / s -> 2 / w as s -> 0
    return v * torch.where(s > 1e-7, angle / s.clamp_min(1e-12), 2.0 / w.clamp_min(1e-12))


def quat_angle(q1: torch.Tensor, q2: torch.Tensor) -> torch.Tensor:
    """Angle (rad, in [0, pi]) of the rotation taking q1 to q2 (atan2 form: exact near 0)."""
    d = quat_mul(q2, quat_inv(q1))
    return 2.0 * torch.atan2(torch.linalg.norm(d[..., 1:], dim=-1), d[..., 0].abs())


def pose_mul(p1, q1, p2, q2):
    """T1 * T2."""
    return p1 + quat_apply(q1, p2), quat_mul(q1, q2)


def pose_inv(p, q):
    qi = quat_inv(q)
    return -quat_apply(qi, p), qi


def relative_pose(p_frame, q_frame, p, q):
    """Pose (p, q) expressed in the frame (p_frame, q_frame): T_frame^-1 * T."""
    qi = quat_inv(q_frame)
    return quat_apply(qi, p - p_frame), quat_positive(quat_mul(qi, q))


def slerp_toward(q_from: torch.Tensor, q_to: torch.Tensor, max_angle: float | torch.Tensor) -> torch.Tensor:
    """Rotate ``q_from`` towards ``q_to`` by at most ``max_angle`` radians (geodesic)."""
    dq = quat_mul(q_to, quat_inv(q_from))
    rv = quat_to_axis_angle(dq)
    angle = torch.linalg.norm(rv, dim=-1, keepdim=True)
    frac = torch.clamp(max_angle / angle.clamp_min(1e-9), max=1.0)
    step = quat_from_axis_angle(rv / angle.clamp_min(1e-9), (angle * frac).squeeze(-1))
    return quat_positive(quat_mul(step, q_from))


# ----------------------------------------------------------------------------- closest points
SHAPE_BOX, SHAPE_CYLINDER, SHAPE_SPHERE, SHAPE_PRISM, SHAPE_MESH = 0, 1, 2, 3, 4


def closest_point_box(p: torch.Tensor, half: torch.Tensor) -> torch.Tensor:
    """Closest point on the surface of an axis-aligned box with half extents ``half`` [..., 3]."""
    q = torch.maximum(torch.minimum(p, half), -half)
    inside = (p.abs() <= half).all(dim=-1, keepdim=True)
    gap = half - p.abs()
    axis = torch.argmin(gap, dim=-1, keepdim=True)
    onehot = torch.zeros_like(p).scatter_(-1, axis, 1.0).bool()
    face = torch.where(onehot, torch.copysign(half, p), p)
    return torch.where(inside, face, q)


def closest_point_prism(p: torch.Tensor, radius: torch.Tensor, half_len: torch.Tensor,
                        n_sides: torch.Tensor) -> torch.Tensor:
    """Closest point on a right prism along local x with a regular ``n_sides``-gon cross-section
    of circumradius ``radius`` (``n_sides <= 0`` means a circular cross-section: a cylinder).

    Edges of the polygon have outward normals at angles ``2*pi*k/n`` in the (y, z) plane.
    The prism is the product of a convex polygon and an interval, so outside points project
    per factor; inside points move to the nearer of the side and the caps.
    """
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    circ = n_sides <= 0
    n = torch.where(circ, torch.full_like(n_sides, 4.0), n_sides)
    sector = 2.0 * math.pi / n
    theta = torch.atan2(z, y)
    k = torch.round(theta / sector)
    phi = k * sector  # normal angle of the facing edge
    c, s = torch.cos(phi), torch.sin(phi)
    u = y * c + z * s          # along the edge normal
    w = -y * s + z * c         # along the edge
    apothem = radius * torch.cos(math.pi / n)
    half_edge = radius * torch.sin(math.pi / n)
    r = torch.sqrt(y * y + z * z)
    # polygon: the facing edge; circle: the radial direction
    u_n = torch.where(circ, r, u)
    a = torch.where(circ, radius, apothem)
    inside2d = u_n <= a
    w_c = torch.clamp(w, -half_edge, half_edge)
    # 2-D projection onto the boundary
    py_poly, pz_poly = a * c - w_c * s, a * s + w_c * c
    scale = radius / r.clamp_min(1e-12)
    py_circ = torch.where(r > 1e-12, y * scale, radius)
    pz_circ = torch.where(r > 1e-12, z * scale, torch.zeros_like(z))
    by = torch.where(circ, py_circ, py_poly)
    bz = torch.where(circ, pz_circ, pz_poly)
    # the side point keeps the along-edge coordinate when inside
    sy_poly, sz_poly = a * c - w * s, a * s + w * c
    sy = torch.where(circ, py_circ, sy_poly)
    sz = torch.where(circ, pz_circ, sz_poly)
    inside_ax = x.abs() <= half_len
    xc = torch.clamp(x, -half_len, half_len)
    out_y = torch.where(inside2d, y, by)
    out_z = torch.where(inside2d, z, bz)
    d_side = a - u_n
    d_cap = half_len - x.abs()
    to_side = d_side < d_cap
    in_y = torch.where(to_side, sy, y)
    in_z = torch.where(to_side, sz, z)
    in_x = torch.where(to_side, x, torch.copysign(half_len, x))
    inside = inside2d & inside_ax
    return torch.stack([torch.where(inside, in_x, xc), torch.where(inside, in_y, out_y),
                        torch.where(inside, in_z, out_z)], dim=-1)


def closest_point_sphere(p: torch.Tensor, radius: torch.Tensor) -> torch.Tensor:
    n = torch.linalg.norm(p, dim=-1, keepdim=True)
    fallback = torch.zeros_like(p)
    fallback[..., 0] = 1.0
    d = torch.where(n > 1e-12, p / n.clamp_min(1e-12), fallback)
    return d * radius.unsqueeze(-1)


def closest_point_triangles(p: torch.Tensor, tris: torch.Tensor) -> torch.Tensor:
    """Closest point on a triangle soup.

    p: [B, L, 3] query points; tris: [B, F, 3, 3] triangles (padding may repeat a triangle).
    Returns [B, L, 3]. Ericson, Real-Time Collision Detection, 5.1.5, vectorised.
    """
    a, b, c = tris[:, None, :, 0], tris[:, None, :, 1], tris[:, None, :, 2]  # [B,1,F,3]
    P = p[:, :, None, :]  # [B,L,1,3]
    ab, ac, ap = b - a, c - a, P - a
    d1, d2 = (ab * ap).sum(-1), (ac * ap).sum(-1)
    bp = P - b
    d3, d4 = (ab * bp).sum(-1), (ac * bp).sum(-1)
    cp = P - c
    d5, d6 = (ab * cp).sum(-1), (ac * cp).sum(-1)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    eps = 1e-18
    denom = (va + vb + vc)
    v = vb / torch.where(denom.abs() > eps, denom, torch.full_like(denom, eps))
    w = vc / torch.where(denom.abs() > eps, denom, torch.full_like(denom, eps))
    res = a + ab * v.unsqueeze(-1) + ac * w.unsqueeze(-1)  # interior
    # edge BC
    t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6)).clamp_min(eps)
    m = (va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0)
    res = torch.where(m.unsqueeze(-1), b + (c - b) * t_bc.unsqueeze(-1), res)
    # edge AC
    t_ac = d2 / (d2 - d6).clamp_min(eps)
    m = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
    res = torch.where(m.unsqueeze(-1), a + ac * t_ac.unsqueeze(-1), res)
    # edge AB
    t_ab = d1 / (d1 - d3).clamp_min(eps)
    m = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
    res = torch.where(m.unsqueeze(-1), a + ab * t_ab.unsqueeze(-1), res)
    # vertices
    res = torch.where(((d6 >= 0) & (d5 <= d6)).unsqueeze(-1), c.expand_as(res), res)
    res = torch.where(((d3 >= 0) & (d4 <= d3)).unsqueeze(-1), b.expand_as(res), res)
    res = torch.where(((d1 <= 0) & (d2 <= 0)).unsqueeze(-1), a.expand_as(res), res)
    dist = ((res - P) ** 2).sum(-1)  # [B,L,F]
    idx = dist.argmin(dim=-1)  # [B,L]
    return torch.gather(res, 2, idx[..., None, None].expand(-1, -1, 1, 3)).squeeze(2)


def closest_point_shapes(p: torch.Tensor, shape_type: torch.Tensor, params: torch.Tensor,
                         tris: torch.Tensor | None = None, kinds: frozenset | None = None) -> torch.Tensor:
    """Closest surface point for points ``p`` [B, L, 3] given in each object's frame.

    shape_type [B] (SHAPE_*), params [B, 4]:
      box (hx, hy, hz, -), cylinder (radius, half_len, -, -) along x, sphere (radius, -, -, -),
      prism (circumradius, half_len, n_sides, -) along x, mesh (uses ``tris`` [B, F, 3, 3]).
    The formula of every shape kind present runs for the whole batch and each object selects its
    own, so a batch may mix shapes (heterogeneous objects across parallel envs). ``kinds`` (the
    set of SHAPE_* present, known when the scene is built) skips absent kinds.
    """
    kinds = kinds if kinds is not None else frozenset({SHAPE_BOX, SHAPE_CYLINDER, SHAPE_SPHERE, SHAPE_PRISM}
                                                      | ({SHAPE_MESH} if tris is not None else set()))
    st = shape_type[:, None, None]
    pr = params[:, None, :].expand(-1, p.shape[1], -1)
    out = None

    def put(mask_kinds, value):
        nonlocal out
        if out is None or len(kinds) == 1:
            out = value
        else:
            m = st == mask_kinds[0] if len(mask_kinds) == 1 else (st == mask_kinds[0]) | (st == mask_kinds[1])
            out = torch.where(m, value, out)

    if SHAPE_BOX in kinds:
        put((SHAPE_BOX,), closest_point_box(p, pr[..., :3]))
    if SHAPE_CYLINDER in kinds or SHAPE_PRISM in kinds:
        n_sides = pr[..., 2] if SHAPE_CYLINDER not in kinds else \
            torch.where(st[..., 0] == SHAPE_CYLINDER, torch.zeros_like(pr[..., 2]), pr[..., 2])
        put((SHAPE_CYLINDER, SHAPE_PRISM), closest_point_prism(p, pr[..., 0], pr[..., 1], n_sides))
    if SHAPE_SPHERE in kinds:
        put((SHAPE_SPHERE,), closest_point_sphere(p, pr[..., 0]))
    if SHAPE_MESH in kinds:
        put((SHAPE_MESH,), closest_point_triangles(p, tris))
    return out
