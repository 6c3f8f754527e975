"""Link poses from forward kinematics inside the compiled step math, against reading them from SAPIEN.

The step reads the pose of every tracked body (hand frame, 21 contact links and the object for the
Allegro hand) with one SAPIEN call each after every control step (``HandObjectSensor.poses``).
PhysX articulations are reduced-coordinate, so the link poses also follow from the root link's pose
and the joint positions alone: two reads instead of 23, and forward kinematics in the compiled
graph. This script measures whether that pays on the CPU, and checks the kinematics against PhysX:

  * the largest difference between forward kinematics and PhysX's link poses (a few 1e-7);
  * us per call, hot loop: reading the 23 poses, reading the root and the object, and the forward
    kinematics of the 28 links needed (the 22 tracked ones and their ancestors) compiled alone as
    ``GraphMethod`` compiles the step math (Inductor, C++ wrapper) and eagerly.

Measured on 2 cores (2026-11-24): the compiled kinematics cost ~39-43 us a call, against ~29 us for the
23 reads it would replace (hot; ~45 us inside the step loop); inside the step math the graph grew
from ~84 to ~129 us, and full steps with it were no faster (rotate, 5 interleaved repetitions:
+3%, -4%, -4%, -5%), so the step keeps its reads. What the graph spends is Inductor's per-level
buffers and loop nests around ~1,500 flops, not the arithmetic.

    python benchmarks/fk_vs_reads.py [--hand allegro] [--json out.json]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from typing import List, Sequence

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from env_throughput import _holding_env, held_objects  # noqa: E402
from unicross.compiling import GraphMethod  # noqa: E402

_REVOLUTE = ("revolute", "revolute_unwrapped")


def _parts(x):
    return x.unbind(-1) if torch.is_tensor(x) else x


def _pack(parts, like):
    return torch.stack(parts, -1) if torch.is_tensor(like) else np.array(parts, dtype=np.float64)


def _qmul(a, b):
    """Hamilton product (wxyz) written out per component (fused by Inductor, unlike
    ``geometry.quat_mul``'s small matrix product): tensors [..., 4] or float sequences."""
    aw, ax, ay, az = _parts(a)
    bw, bx, by, bz = _parts(b)
    return _pack((aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                  aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw), a)


def _rotate(q, v):
    """Vectors v [..., 3] rotated by unit quaternions q [..., 4] (tensors or float sequences)."""
    w, x, y, z = _parts(q)
    vx, vy, vz = _parts(v)
    tx, ty, tz = 2 * (y * vz - z * vy), 2 * (z * vx - x * vz), 2 * (x * vy - y * vx)
    return _pack((vx + w * tx + y * tz - z * ty, vy + w * ty + z * tx - x * tz, vz + w * tz + x * ty - y * tx), v)


class KinematicChain:
    """The kinematic tree of one articulation, cut down to the given links and their ancestors.

    ``chain(root_p, root_q, qpos)`` -> positions [B, T, 3] and quaternions (wxyz) [B, T, 4] of the
    T target links, from the root link's pose [B, 3] / [B, 4] and the articulation's joint positions
    [B, dof] (SAPIEN's active-joint order).

    The math is written per scalar component with the joints' fixed frames folded into constants
    (float64 here, Python floats in the graph), so that Inductor fuses the whole tree into one loop:
    the links are batched by depth in the tree (one batch per level). A revolute joint's local pose is ``c * K0 + s * K1`` (c, s: cosine and
    sine of half its angle) for its rotation and ``u0 + u1 cos q + u2 sin q`` for its translation;
    a prismatic one's is ``K0`` and ``u0 + q u1``."""

    def __init__(self, parents: Sequence[int], joints: Sequence[tuple], targets: Sequence[int], device=None):
        """``parents[i]``: the parent of link i (-1 for the root, which comes first; parents before
        children); ``joints[i]``: ``(kind, qpos index, pose_in_parent, pose_in_child)`` of the joint
        above link i, poses as (p [3], q [4] wxyz), kind ``revolute``, ``prismatic`` or ``fixed``;
        ``targets``: the links whose poses the chain returns."""
        if not parents or parents[0] != -1 or any(not (0 <= p < i) for i, p in enumerate(parents) if i):
            raise ValueError("links must come parents first, the root alone at index 0")
        n = len(parents)
        depth = [0] * n
        for i in range(1, n):
            depth[i] = depth[parents[i]] + 1
        # links grouped by depth: level d is computed from level d-1 in one batch
        self.levels = [[i for i in range(n) if depth[i] == d] for d in range(max(depth) + 1)]
        slot = {i: k for level in self.levels for k, i in enumerate(level)}
        order = [i for level in self.levels for i in level]
        t = lambda x, dtype=torch.float32: torch.as_tensor(np.asarray(x), dtype=dtype, device=device)  # noqa: E731
        self.level_links = [t(level, torch.long) for level in self.levels]
        self.level_parents = [t([slot[parents[i]] for i in level], torch.long) for level in self.levels[1:]]
        self.targets = t([order.index(i) for i in targets], torch.long)
        k0, k1, u0, u1, u2, rev, pri, qidx = [], [], [], [], [], [], [], []
        for kind, k, (pa, qa), (pc, qc) in joints:
            qa, qb = np.asarray(qa, np.float64), _conj(np.asarray(qc, np.float64))
            pb = -np.asarray(_rotate(qb, np.asarray(pc, np.float64)))  # pose_in_child inverted
            pa = np.asarray(pa, np.float64)
            if kind not in ("revolute", "prismatic", "fixed"):
                raise ValueError(f"joint kind {kind!r}")
            k0.append(_qmul(qa, qb))
            k1.append(_qmul(_qmul(qa, (0.0, 1.0, 0.0, 0.0)), qb))
            if kind == "revolute":  # x-rotation by q of pb: (pb_x, 0, 0) + cos q (0, pb_y, pb_z) + sin q (0, -pb_z, pb_y)
                u0.append(pa + _rotate(qa, (pb[0], 0.0, 0.0)))
                u1.append(_rotate(qa, (0.0, pb[1], pb[2])))
                u2.append(_rotate(qa, (0.0, -pb[2], pb[1])))
            else:  # prismatic: pb moved by q along x; fixed: q = 0
                u0.append(pa + _rotate(qa, pb))
                u1.append(_rotate(qa, (1.0, 0.0, 0.0)))
                u2.append((0.0, 0.0, 0.0))
            rev.append(kind == "revolute")
            pri.append(kind == "prismatic")
            qidx.append(max(k, 0))
        self.k0, self.k1, self.u0, self.u1, self.u2 = (t(np.array(x, np.float64)) for x in (k0, k1, u0, u1, u2))
        self.revolute, self.prismatic, self.qidx = t(rev), t(pri), t(qidx, torch.long)

    @classmethod
    def from_articulation(cls, art, links: List, device=None) -> "KinematicChain":
        """From a SAPIEN ``PhysxArticulation`` and the ``PhysxArticulationLinkComponent``\\ s whose
        poses it returns (in that order)."""
        joint_of = {j.child_link: j for j in art.joints}
        active = {j.child_link: i for i, j in enumerate(art.active_joints)}
        needed = set()
        for link in links:  # the targets and their ancestors
            while link is not None and link not in needed:
                needed.add(link)
                link = joint_of[link].parent_link
        order = [l for l in art.links if l in needed]  # SAPIEN lists links parents first
        index = {l: i for i, l in enumerate(order)}
        parents, joints = [], []
        for link in order:
            j = joint_of[link]
            parents.append(-1 if j.parent_link is None else index[j.parent_link])
            kind = "fixed" if j.parent_link is None else j.type  # the root's pose is given
            kind = "revolute" if kind in _REVOLUTE else kind
            if kind not in ("revolute", "prismatic", "fixed"):
                raise ValueError(f"joint {j.name!r}: type {j.type!r} is not supported")
            if kind != "fixed" and j.child_link not in active:
                raise ValueError(f"joint {j.name!r} moves but is not an active joint")
            joints.append((kind, active.get(j.child_link, -1), (j.pose_in_parent.p, j.pose_in_parent.q),
                           (j.pose_in_child.p, j.pose_in_child.q)))
        return cls(parents, joints, [index[l] for l in links], device)

    def __call__(self, root_p: torch.Tensor, root_q: torch.Tensor, qpos: torch.Tensor):
        q = qpos[:, self.qidx]
        rev, pri = self.revolute, self.prismatic
        c = rev * torch.cos(0.5 * q) + (1.0 - rev)
        s = rev * torch.sin(0.5 * q)
        a = rev * torch.cos(q) + pri * q
        b = rev * torch.sin(q)
        local_q = c[..., None] * self.k0 + s[..., None] * self.k1           # [B, n, 4]
        local_p = self.u0 + a[..., None] * self.u1 + b[..., None] * self.u2   # [B, n, 3]
        pos, quat = [root_p[:, None]], [root_q[:, None]]
        for links, parents in zip(self.level_links[1:], self.level_parents):
            pp, pq = pos[-1][:, parents], quat[-1][:, parents]
            pos.append(pp + _rotate(pq, local_p[:, links]))
            quat.append(_qmul(pq, local_q[:, links]))
        return torch.cat(pos, 1)[:, self.targets], torch.cat(quat, 1)[:, self.targets]


def _conj(q):
    return np.array([q[0], -q[1], -q[2], -q[3]])


def _per_call(fn, n=3000) -> float:
    for _ in range(50):
        fn()
    t = time.perf_counter()
    for _ in range(n):
        fn()
    return (time.perf_counter() - t) / n * 1e6


class _Owner:
    """What ``GraphMethod`` compiles: a method of an object (here the chain alone)."""

    def __init__(self, chain):
        self.chain = chain

    def fk(self, root_p, root_q, qpos):
        return self.chain(root_p, root_q, qpos)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--hand", default="allegro")
    p.add_argument("--json", default=None)
    args = p.parse_args()
    torch.set_num_threads(1)
    gs, objects = held_objects(args.hand)
    env, u = _holding_env("UniCross-Rotate-v1", {"axis": "z+"}, gs, objects, hand=args.hand)
    g = torch.Generator().manual_seed(0)
    for _ in range(20):  # a holding hand with its joints away from zero
        u.step((torch.rand(1, u.hand_spec.dof, generator=g) * 2 - 1) * 0.3)
    art = u.agent.robot._objs[0]
    links = u.sensor._components[:-1]
    chain = KinematicChain.from_articulation(art, links)
    root_p = torch.tensor(np.asarray(art.root_pose.p), dtype=torch.float32)[None]
    root_q = torch.tensor(np.asarray(art.root_pose.q), dtype=torch.float32)[None]
    qpos = u.agent.robot.get_qpos()
    pos, quat = u.sensor.poses()
    fp, fq = chain(root_p, root_q, qpos)
    err_p = float((fp - pos[:, :-1]).abs().max())
    err_q = float((fq - quat[:, :-1]).abs().max())
    owner = _Owner(chain)  # GraphMethod holds its owner weakly
    compiled = GraphMethod(owner, _Owner.fk)
    cp, cq = compiled(root_p, root_q, qpos)
    err_c = float(torch.maximum((cp - fp).abs().max(), (cq - fq).abs().max()))
    comps = [art.root, u.sensor._components[-1]]
    row = dict(
        bodies_read=len(u.sensor._components), links_in_chain=sum(len(level) for level in chain.levels),
        max_position_error_m=err_p, max_quaternion_error=err_q, compiled_vs_eager=err_c,
        us_read_all_poses=_per_call(u.sensor.poses),
        us_read_root_and_object=_per_call(lambda: torch.from_numpy(np.array(
            [c.entity_pose.__getstate__() for c in comps], dtype=np.float32))),
        us_fk_compiled=_per_call(lambda: compiled(root_p, root_q, qpos)),
        us_fk_eager=_per_call(lambda: chain(root_p, root_q, qpos), n=100))
    env.close()
    for k, v in row.items():
        print(f"{k:28s} {v:.3g}" if isinstance(v, float) else f"{k:28s} {v}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(row, f, indent=1)


if __name__ == "__main__":
    main()
