"""Batched reads of link poses and hand-object contact forces, for CPU and GPU PhysX.

Both backends return the same tensors on the env device:
  * ``poses()``           -> positions [N, B, 3] and quaternions [N, B, 4] of the tracked bodies
                             (hand frame, contact links, object), one gather per step;
  * ``contact_forces()``  -> net contact force vector between each contact link and the object,
                             [N, L, 3], in Newtons;
  * ``apply_object_force(f)`` applies an external force to the object for the next sim step.
On the GPU we use one pair-impulse query for all (link, object) pairs of all envs; on the CPU
(one env per process) we read all contacts in one pass and accumulate per link, which costs a
fraction of per-pair queries. Positions are in each env's own frame on both backends: with
ManiSkill's ``parallel_in_single_scene`` (every GPU env in one viewer) PhysX holds them with the
envs' scene offsets added, which the GPU read subtracts, as ManiSkill's own pose getters do.
"""
from __future__ import annotations

from typing import List

import numpy as np
import torch


class HandObjectSensor:
    def __init__(self, scene, hand_frame, links: List, obj):
        """hand_frame and links are ManiSkill ``Link`` structs, obj an ``Actor`` struct."""
        self.scene = scene
        self.device = scene.device
        self.gpu = scene.gpu_sim_enabled
        self.num_links = len(links)
        bodies = [hand_frame] + list(links) + [obj]
        if self.gpu:
            self._index = torch.cat([b._body_data_index for b in bodies]).to(self.device)
            self._obj_index = obj._body_data_index.to(self.device)
            pairs = [(link._bodies[e], obj._bodies[e]) for link in links for e in range(scene.num_envs)]
            self._query = scene.px.gpu_create_contact_pair_impulse_query(pairs)
            self._offsets = None  # [N, B, 3] scene offsets of the bodies' envs, where PhysX adds them
            if getattr(scene, "parallel_in_single_scene", False):
                idx = torch.cat([b._scene_idxs for b in bodies]).to(self.device)
                self._offsets = scene.scene_offsets[idx].to(torch.float32).view(
                    len(bodies), scene.num_envs, 3).transpose(0, 1)
        else:
            self._components = [b._bodies[0] for b in bodies]
            # contacts name their bodies by component; SAPIEN hands back the same Python object for a
            # live component, so identity lookups replace two entity-id reads per contact (~25 us a step)
            self._link_of_body = {l._bodies[0]: i for i, l in enumerate(links)}
            self._obj_body = obj._bodies[0]
            self._zero3 = np.zeros(3, dtype=np.float32)
        self._num_bodies = len(bodies)

    def poses(self):
        if self.gpu:
            data = self.scene.px.cuda_rigid_body_data.torch()[self._index, :7]  # [B*N, 7], body-major
            data = data.view(self._num_bodies, self.scene.num_envs, 7).transpose(0, 1)
            pos = data[..., :3] if self._offsets is None else data[..., :3] - self._offsets
            return pos, data[..., 3:]
        # a Pose's 7 numbers as one tuple (its pickle state) instead of two numpy arrays: 137 -> 40 us
        # a step for the 23 bodies of the Allegro hand; float32 -> float -> float32 is exact
        data = torch.from_numpy(np.array([c.entity_pose.__getstate__() for c in self._components],
                                         dtype=np.float32))[None]
        return data[..., :3], data[..., 3:]

    def contact_forces(self) -> torch.Tensor:
        dt = self.scene.px.timestep
        if self.gpu:
            self.scene.px.gpu_query_contact_pair_impulses(self._query)
            imp = self._query.cuda_impulses.torch().view(self.num_links, self.scene.num_envs, 3)
            return imp.transpose(0, 1) / dt
        obj, lookup = self._obj_body, self._link_of_body
        out = np.zeros((self.num_links, 3), dtype=np.float32)
        for c in self.scene.px.get_contacts():  # one pass, each point's impulse added in place to its link's row
            b0, b1 = c.bodies
            if b0 is obj:
                link = lookup.get(b1)
                if link is not None:
                    row = out[link]
                    for p in c.points:
                        row -= p.impulse
            elif b1 is obj:
                link = lookup.get(b0)
                if link is not None:
                    row = out[link]
                    for p in c.points:
                        row += p.impulse
        return torch.from_numpy(out / dt)[None]

    def apply_object_force(self, force) -> None:
        """External force [N, 3] (world, Newtons) on the object's centre of mass for the next sim
        step: a tensor on the env device (GPU) or, on the CPU, a [N, 3] tensor or one float32 [3] array."""
        if self.gpu:
            self.scene.px.cuda_rigid_body_force.torch()[self._obj_index, :3] = force
            self.scene.px.gpu_apply_rigid_dynamic_force()
        else:
            self._obj_body.add_force_torque(force[0].numpy() if isinstance(force, torch.Tensor) else force, self._zero3)
