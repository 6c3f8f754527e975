"""Forward kinematics of a SAPIEN articulation in batched torch: link poses from the root pose and
the joint positions.

On the CPU, reading a link's pose from PhysX is one Python call and two small arrays per link
(~3 us each, ~70 us for the 22 tracked bodies of the Allegro hand); computing the same poses from
the joint positions (already read) inside the compiled step math costs a few microseconds of fused
kernel. :class:`ArticulationFK` holds, for each requested link, the chain of joints from the root:
constant transforms between the movable joints, and which joint position drives each of them.

PhysX conventions (SAPIEN 3): a joint moves its child about (revolute) or along (prismatic) the x
axis of the joint frame; ``link = parent · pose_in_parent · J(q) · pose_in_child⁻¹``. A reduced-
coordinate articulation's link poses are exactly this function of its root pose and joint positions,
so the two agree to float rounding (``tests/test_kinematics.py``).
"""
from __future__ import annotations

from typing import List, Sequence, Tuple

import torch

from unicross.geometry import pose_mul

_MOVABLE = {"revolute": "r", "revolute_unwrapped": "r", "prismatic": "p"}


def _pose_mul(a: Tuple[torch.Tensor, torch.Tensor], b: Tuple[torch.Tensor, torch.Tensor]):
    return pose_mul(*a, *b)


def _pose(p) -> Tuple[torch.Tensor, torch.Tensor]:
    return torch.tensor(p.p, dtype=torch.float64), torch.tensor(p.q, dtype=torch.float64)


class ArticulationFK:
    """World poses of ``links`` (physx link components of ``articulation``) from its root pose and
    its joint positions (``qpos`` in the articulation's active-joint order).

    Each link's chain is stored as ``depth`` levels (the most movable joints on any of the chains,
    the shorter ones padded with identity levels driven by a zero joint position):
    ``pose = root · C_0 · J_0(q) · C_1 · J_1(q) · ... · C_depth``, all links of a level in one
    batched product."""

    def __init__(self, articulation, links: Sequence, device="cpu"):
        active = [j.name for j in articulation.active_joints]
        self.dof = len(active)
        chains: List[List[tuple]] = []  # per link: [(fixed transform before the joint, kind, qpos index)], tail
        tails = []
        for link in links:
            steps, fixed = [], (torch.zeros(3, dtype=torch.float64), torch.tensor([1.0, 0, 0, 0], dtype=torch.float64))
            path = []
            node = link
            while node.parent is not None:
                path.append(node)
                node = node.parent
            for node in reversed(path):  # from the root's child down to the link
                j = node.joint
                kind = _MOVABLE.get(j.type)
                fixed = _pose_mul(fixed, _pose(j.pose_in_parent))
                child_inv = _pose(j.pose_in_child.inv())
                if kind is None:
                    if j.type != "fixed":
                        raise ValueError(f"joint {j.name!r} of type {j.type!r}: forward kinematics handles fixed, "
                                         f"revolute and prismatic joints")
                    fixed = _pose_mul(fixed, child_inv)
                    continue
                steps.append((fixed, kind, active.index(j.name)))
                fixed = child_inv
            chains.append(steps)
            tails.append(fixed)
        depth = max((len(c) for c in chains), default=0)
        n = len(links)
        ident = (torch.zeros(3, dtype=torch.float64), torch.tensor([1.0, 0, 0, 0], dtype=torch.float64))
        cp = torch.zeros(depth, n, 3, dtype=torch.float64)
        cq = torch.zeros(depth, n, 4, dtype=torch.float64)
        revolute = torch.zeros(depth, n, dtype=torch.bool)
        qi = torch.full((depth, n), self.dof, dtype=torch.long)  # index dof: a zero column (padding)
        for k, steps in enumerate(chains):
            # pad at the front: identity levels before the chain leave the product unchanged
            pad = depth - len(steps)
            for d in range(depth):
                if d < pad:
                    cp[d, k], cq[d, k] = ident
                else:
                    fixed, kind, idx = steps[d - pad]
                    cp[d, k], cq[d, k] = fixed
                    revolute[d, k] = kind == "r"
                    qi[d, k] = idx
        f32 = dict(dtype=torch.float32, device=device)
        self.depth = depth
        self.cp, self.cq = cp.to(**f32), cq.to(**f32)
        self.revolute = revolute.to(device)
        self.qi = qi.to(device)
        self.tail_p = torch.stack([t[0] for t in tails]).to(**f32)
        self.tail_q = torch.stack([t[1] for t in tails]).to(**f32)

    def __call__(self, root_p: torch.Tensor, root_q: torch.Tensor, qpos: torch.Tensor):
        """root pose [N, 3], [N, 4] and qpos [N, dof] -> link positions [N, L, 3], quaternions [N, L, 4]."""
        n, L = qpos.shape[0], self.tail_p.shape[0]
        q = torch.cat([qpos, qpos.new_zeros(n, 1)], dim=-1)
        p, r = root_p[:, None].expand(n, L, 3), root_q[:, None].expand(n, L, 4)
        for d in range(self.depth):
            p, r = _pose_mul((p, r), (self.cp[d].expand(n, L, 3), self.cq[d].expand(n, L, 4)))
            a = q[:, self.qi[d]]                                   # [N, L] joint position of this level
            rev = self.revolute[d]
            half = 0.5 * a
            zero = torch.zeros_like(a)
            jq = torch.stack([torch.where(rev, torch.cos(half), torch.ones_like(a)),
                              torch.where(rev, torch.sin(half), zero), zero, zero], dim=-1)
            jp = torch.stack([torch.where(rev, zero, a), zero, zero], dim=-1)
            p, r = _pose_mul((p, r), (jp, jq))
        return _pose_mul((p, r), (self.tail_p.expand(n, L, 3), self.tail_q.expand(n, L, 4)))
