"""Compact trajectory files of rollouts, recorded without any renderer.

A trajectory (``.npz``) holds, per control step, the hand's joint positions (hand-spec order),
the hand-frame world pose, the object world pose, the mode, per-link contact flags and forces and
the contact points (nearest object-surface point of each link), plus metadata: hand name, object
description (shape, dimensions or mesh path), whether a table was present, task id, control rate.
:mod:`unicross.render` turns it into frames; the hand is placed by forward kinematics of the
hand's own URDF from the recorded joints.
"""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Dict, List, Optional

import numpy as np
import torch

from unicross import formulation as F
from unicross.geometry import quat_apply

FORMAT = "unicross-trajectory/1"


class TrajectoryRecorder:
    """Collects steps of env ``env_index`` of an unwrapped UniCross task ``u``.

    Call :meth:`record` after ``reset`` and after every ``step`` (optionally with a ``label``,
    e.g. the phase of a chain), then :meth:`save`."""

    def __init__(self, u, env_index: int = 0, task_id: Optional[str] = None):
        self.u, self.e = u, env_index
        spec = u.env_objects[env_index]
        self.meta = dict(format=FORMAT, hand=u.hand_spec.name, joint_names=u.hand_spec.joint_names,
                         contact_links=u.hand_spec.contact_links, object=dataclasses.asdict(spec),
                         table=bool(u.cfg["table"]), task=task_id or type(u).__name__,
                         control_freq=int(round(1.0 / u.control_dt)), modes=list(F.MODES))
        self.rows: Dict[str, List[np.ndarray]] = {k: [] for k in
                                                  ("qpos", "wrist_pose", "object_pose", "mode", "contact", "force",
                                                   "contact_points", "step")}
        self.labels: List[str] = []

    def record(self, label: str = "") -> None:
        u, e = self.u, self.e
        pos, quat = u.sensor.poses()
        parts = u._measured  # true contacts and distances, whatever the observation ablates
        vec_h = parts["vec"][e]  # link -> surface, hand frame
        hand_q = quat[e, 0]
        probe_w = pos[e, 1:-1] + quat_apply(quat[e, 1:-1], u.link_probe)
        surface_w = probe_w + quat_apply(hand_q.expand(vec_h.shape[0], 4), vec_h)
        r = self.rows
        r["qpos"].append(parts["qpos"][e].cpu().numpy().copy())
        r["wrist_pose"].append(torch.cat([pos[e, 0], hand_q]).cpu().numpy())
        r["object_pose"].append(torch.cat([pos[e, -1], quat[e, -1]]).cpu().numpy())
        r["mode"].append(np.int64(u.mode[e].item()))
        r["contact"].append(parts["contact"][e].cpu().numpy().astype(bool))
        r["force"].append(parts["force"][e].cpu().numpy())
        r["contact_points"].append(surface_w.cpu().numpy())
        r["step"].append(np.int64(u.elapsed_steps[e].item()))
        self.labels.append(label)

    def __len__(self):
        return len(self.labels)

    def save(self, path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        arrays = {k: np.stack(v) for k, v in self.rows.items()}
        meta = dict(self.meta, labels=self.labels)
        np.savez_compressed(path, meta=np.array(json.dumps(meta)), **arrays)
        return path


@dataclasses.dataclass
class Trajectory:
    meta: dict
    qpos: np.ndarray           # [T, dof]
    wrist_pose: np.ndarray     # [T, 7]
    object_pose: np.ndarray    # [T, 7]
    mode: np.ndarray           # [T]
    contact: np.ndarray        # [T, L] bool
    force: np.ndarray          # [T, L]
    contact_points: np.ndarray  # [T, L, 3]
    step: np.ndarray           # [T]

    def __len__(self):
        return len(self.mode)

    @property
    def labels(self) -> List[str]:
        return self.meta.get("labels", [""] * len(self))

    @staticmethod
    def load(path) -> "Trajectory":
        path = Path(path)
        if not path.exists():
            raise FileNotFoundError(f"trajectory not found: {path}")
        if path.suffix in (".h5", ".hdf5"):
            raise ValueError(f"{path} is an HDF5 file (ManiSkill's RecordEpisode writes those); unicross render reads "
                             f"UniCross trajectory files ({FORMAT}, .npz) written by `unicross eval --videos K` or "
                             f"`unicross chain --video`; render a RecordEpisode run with its save_video=True")
        try:
            z = np.load(path, allow_pickle=False)
            meta = json.loads(str(z["meta"]))
        except Exception as e:
            raise ValueError(f"{path} is not a UniCross trajectory file ({FORMAT}, .npz): {type(e).__name__}") from None
        if meta.get("format") != FORMAT:
            raise ValueError(f"{path} is not a {FORMAT} file")
        return Trajectory(meta, *(z[k] for k in ("qpos", "wrist_pose", "object_pose", "mode", "contact", "force",
                                                  "contact_points", "step")))
