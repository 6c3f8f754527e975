"""Render trajectory files to video (mp4/gif) or stills (png), with or without a GPU.

Without a GPU: ``pyrender`` offscreen on EGL (Mesa llvmpipe on a CPU; Debian ``libegl1`` and
``libgl1-mesa-dri``). The hand is drawn with its own visual meshes, placed by forward kinematics
of its URDF from the recorded joints; the object from its exact geometry; the table as a slab;
contact points as red markers; a label with the mode (or chain phase) and step.

With a rendering device (``--renderer sapien``, or ``auto`` when SAPIEN can render) the same
trajectory is replayed into a ManiSkill scene and captured by a SAPIEN camera.
"""
from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Dict, List, Optional, Tuple

import numpy as np

from unicross.trajectory import Trajectory

CAMERAS = ("front", "side", "top", "follow")
INSTALL_HINT = ("offscreen rendering needs EGL and Mesa's OpenGL drivers: "
                "apt-get install -y libegl1 libgl1-mesa-dri (and pip install pyrender-maintained)")


class RenderUnavailable(RuntimeError):
    """Raised with one clear message when the display libraries are missing."""


# ----------------------------------------------------------------------------- kinematics
def _rpy_matrix(rpy) -> np.ndarray:
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def _origin(el) -> np.ndarray:
    T = np.eye(4)
    if el is not None:
        T[:3, 3] = [float(v) for v in el.get("xyz", "0 0 0").split()]
        T[:3, :3] = _rpy_matrix([float(v) for v in el.get("rpy", "0 0 0").split()])
    return T


def _axis_angle(axis, angle) -> np.ndarray:
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    x, y, z = axis
    c, s, C = math.cos(angle), math.sin(angle), 1 - math.cos(angle)
    return np.array([[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                     [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                     [z * x * C - y * s, z * y * C + x * s, c + z * z * C]])


def pose_matrix(pose7) -> np.ndarray:
    """(x, y, z, qw, qx, qy, qz) -> 4x4."""
    p, (w, x, y, z) = pose7[:3], pose7[3:]
    T = np.eye(4)
    T[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                 [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                 [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]
    T[:3, 3] = p
    return T


class HandModel:
    """Visual geometry and forward kinematics of a floating hand, from its generated URDF,
    rooted at the hand frame (whose world pose the trajectory records)."""

    def __init__(self, hand: str):
        from unicross.robots.hand import HAND_FRAME_LINK, build_floating_urdf, load_hand
        self.spec = load_hand(hand)
        root = ET.parse(build_floating_urdf(self.spec)).getroot()
        self.visuals: Dict[str, List[Tuple[object, np.ndarray]]] = {}
        for link in root.findall("link"):
            vis = []  # links without visuals (procedural hands) are drawn with their collision shapes
            for v in link.findall("visual") or link.findall("collision"):
                geom = v.find("geometry")
                vis.append((geom, _origin(v.find("origin"))))
            self.visuals[link.get("name")] = vis
        self.children: Dict[str, list] = {}
        self.limits = {j.get("name"): (float(j.find("limit").get("lower", "-inf")), float(j.find("limit").get("upper", "inf")))
                       for j in root.findall("joint") if j.find("limit") is not None}
        for j in root.findall("joint"):
            parent, child = j.find("parent").get("link"), j.find("child").get("link")
            axis = j.find("axis")
            self.children.setdefault(parent, []).append(
                (j.get("name"), j.get("type"), child, _origin(j.find("origin")),
                 [float(a) for a in axis.get("xyz").split()] if axis is not None else [1.0, 0.0, 0.0]))
        self.root = HAND_FRAME_LINK
        self.index = {n: i for i, n in enumerate(self.spec.joint_names)}

    def joint_values(self, qpos: np.ndarray) -> Dict[str, float]:
        """Actuated joint values by name plus the mimic followers derived from them."""
        values = {n: float(qpos[i]) for n, i in self.index.items()}
        for follower, leader, k, o in self.spec.resolved_mimic():
            lo, hi = self.limits.get(follower, (-np.inf, np.inf))
            values[follower] = float(np.clip(k * values[leader] + o, lo, hi))
        return values

    def link_poses(self, wrist_pose: np.ndarray, qpos: np.ndarray) -> Dict[str, np.ndarray]:
        values = self.joint_values(qpos)
        out = {self.root: pose_matrix(wrist_pose)}
        stack = [self.root]
        while stack:
            parent = stack.pop()
            for name, kind, child, origin, axis in self.children.get(parent, []):
                T = out[parent] @ origin
                if kind in ("revolute", "continuous") and name in values:
                    J = np.eye(4)
                    J[:3, :3] = _axis_angle(axis, values[name])
                    T = T @ J
                elif kind == "prismatic" and name in values:
                    J = np.eye(4)
                    J[:3, 3] = np.asarray(axis) * values[name]
                    T = T @ J
                out[child] = T
                stack.append(child)
        return out


# ----------------------------------------------------------------------------- pyrender (CPU)
def _import_pyrender():
    os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
    try:
        import pyrender  # noqa: F401
        return pyrender
    except Exception as e:  # ImportError, OSError from missing libEGL/libGL
        raise RenderUnavailable(f"{INSTALL_HINT} ({type(e).__name__}: {e})") from None


def _look_at(eye, target, up=(0.0, 0.0, 1.0)) -> np.ndarray:
    eye, target, up = map(lambda v: np.asarray(v, float), (eye, target, up))
    z = eye - target
    z /= np.linalg.norm(z)
    x = np.cross(up, z)
    if np.linalg.norm(x) < 1e-6:
        x = np.array([1.0, 0.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, y, z, eye
    return T


CAMERA_OFFSETS = dict(front=(0.5, -0.15, 0.25), side=(0.0, 0.55, 0.2), top=(0.01, 0.0, 0.65), follow=(0.4, -0.2, 0.2))


class PyrenderBackend:
    def __init__(self, traj: Trajectory, width: int, height: int):
        pr = _import_pyrender()
        import trimesh
        self.pr, self.traj = pr, traj
        try:
            self.renderer = pr.OffscreenRenderer(width, height)
        except Exception as e:
            raise RenderUnavailable(f"{INSTALL_HINT} ({type(e).__name__}: {e})") from None
        self.scene = pr.Scene(bg_color=[0.93, 0.94, 0.96, 1.0], ambient_light=[0.35, 0.35, 0.35])
        self.hand = HandModel(traj.meta["hand"])
        self.nodes = []  # (link, node, visual origin)
        hand_mat = pr.MetallicRoughnessMaterial(baseColorFactor=[0.25, 0.27, 0.3, 1.0], metallicFactor=0.1,
                                                roughnessFactor=0.7)
        for link, vis in self.hand.visuals.items():
            for geom, origin in vis:
                mesh = self._geometry(geom, trimesh)
                if mesh is None:
                    continue
                node = self.scene.add(pr.Mesh.from_trimesh(mesh, material=hand_mat, smooth=False))
                self.nodes.append((link, node, origin))
        from unicross.objects import ObjectSpec
        obj = ObjectSpec(**{k: tuple(v) if isinstance(v, list) else v for k, v in traj.meta["object"].items()})
        obj_mat = pr.MetallicRoughnessMaterial(baseColorFactor=[0.85, 0.45, 0.2, 1.0], roughnessFactor=0.6)
        self.obj_node = self.scene.add(pr.Mesh.from_trimesh(obj.trimesh(sections=48), material=obj_mat, smooth=False))
        if traj.meta.get("table", True):
            table = trimesh.creation.box(extents=[1.2, 1.2, 0.05])
            table.apply_translation([0, 0, -0.025])
            tmat = pr.MetallicRoughnessMaterial(baseColorFactor=[0.62, 0.52, 0.42, 1.0], roughnessFactor=0.9)
            self.scene.add(pr.Mesh.from_trimesh(table, material=tmat))
        marker = trimesh.creation.icosphere(subdivisions=2, radius=0.004)
        mmat = pr.MetallicRoughnessMaterial(baseColorFactor=[0.9, 0.05, 0.05, 1.0])
        self.markers = [self.scene.add(pr.Mesh.from_trimesh(marker, material=mmat)) for _ in traj.meta["contact_links"]]
        self.camera = self.scene.add(pr.PerspectiveCamera(yfov=math.radians(45), aspectRatio=width / height))
        self.light = self.scene.add(pr.DirectionalLight(color=np.ones(3), intensity=3.5))
        self.target = traj.wrist_pose[:, :3].mean(0)

    @staticmethod
    def _geometry(geom, trimesh):
        m = geom.find("mesh")
        if m is not None:
            fn = m.get("filename")
            if not fn or not Path(fn).exists():
                return None
            mesh = trimesh.load(fn, force="mesh")
            if m.get("scale"):
                mesh.apply_scale([float(s) for s in m.get("scale").split()])
            return mesh
        b = geom.find("box")
        if b is not None:
            return trimesh.creation.box(extents=[float(s) for s in b.get("size").split()])
        c = geom.find("capsule")
        if c is not None:
            return trimesh.creation.capsule(height=float(c.get("length")), radius=float(c.get("radius")))
        c = geom.find("cylinder")
        if c is not None:
            return trimesh.creation.cylinder(radius=float(c.get("radius")), height=float(c.get("length")))
        s = geom.find("sphere")
        if s is not None:
            return trimesh.creation.icosphere(radius=float(s.get("radius")))
        return None

    def frame(self, t: int, camera: str) -> np.ndarray:
        tr = self.traj
        poses = self.hand.link_poses(tr.wrist_pose[t], tr.qpos[t])
        for link, node, origin in self.nodes:
            self.scene.set_pose(node, poses[link] @ origin)
        self.scene.set_pose(self.obj_node, pose_matrix(tr.object_pose[t]))
        far = np.eye(4)
        far[2, 3] = -100.0
        for i, node in enumerate(self.markers):
            if tr.contact[t, i]:
                T = np.eye(4)
                T[:3, 3] = tr.contact_points[t, i]
                self.scene.set_pose(node, T)
            else:
                self.scene.set_pose(node, far)
        target = tr.wrist_pose[t, :3] if camera == "follow" else self.target
        eye = target + np.asarray(CAMERA_OFFSETS[camera])
        cam = _look_at(eye, target, up=(1.0, 0.0, 0.0) if camera == "top" else (0.0, 0.0, 1.0))
        self.scene.set_pose(self.camera, cam)
        self.scene.set_pose(self.light, cam)
        color, _ = self.renderer.render(self.scene)
        return color

    def close(self):
        self.renderer.delete()


# ----------------------------------------------------------------------------- SAPIEN (GPU)
class SapienBackend:
    """Replays the trajectory into a ManiSkill scene (CPU physics, SAPIEN rendering) and captures
    a camera. Needs a rendering device (GPU)."""

    def __init__(self, traj: Trajectory, width: int, height: int):
        import gymnasium as gym
        import torch
        import unicross  # noqa: F401
        from mani_skill.sensors.camera import CameraConfig
        from unicross.objects import ObjectSpec
        self.torch = torch
        obj = ObjectSpec(**{k: tuple(v) if isinstance(v, list) else v for k, v in traj.meta["object"].items()})
        self.traj = traj
        self.target = traj.wrist_pose[:, :3].mean(0)
        self.size = (width, height)
        self.env = gym.make("UniCross-Grasp-v1", obs_mode="none", sim_backend="physx_cpu", render_backend="gpu",
                            hand=traj.meta["hand"], objects=[obj], randomize=False, compile_math=False,
                            config=dict(table=bool(traj.meta.get("table", True))),
                            human_render_camera_configs=dict(width=width, height=height))
        self.u = self.env.unwrapped
        if not self.u.scene.can_render():
            raise RenderUnavailable("SAPIEN found no rendering device; use --renderer pyrender")
        self.u.reset(seed=0)
        self.CameraConfig = CameraConfig

    def frame(self, t: int, camera: str) -> np.ndarray:
        import sapien
        from mani_skill.utils.structs.pose import Pose
        torch, u, tr = self.torch, self.u, self.traj
        qpos = torch.as_tensor(tr.qpos[t], dtype=torch.float32).clone()
        qpos[:6] = 0.0  # the recorded wrist pose already places the hand frame
        q = u.articulation_qpos(qpos[None])
        u.agent.robot.set_root_pose(Pose.create(torch.as_tensor(tr.wrist_pose[t], dtype=torch.float32)[None]))
        u.agent.robot.set_qpos(q)
        u.obj.set_pose(Pose.create(torch.as_tensor(tr.object_pose[t], dtype=torch.float32)[None]))
        target = tr.wrist_pose[t, :3] if camera == "follow" else self.target
        eye = target + np.asarray(CAMERA_OFFSETS[camera])
        cam = u._human_render_cameras["render_camera"]
        T = _look_at(eye, target, up=(1.0, 0.0, 0.0) if camera == "top" else (0.0, 0.0, 1.0))
        # SAPIEN cameras look along +x with z up: rotate the OpenGL (-z forward, y up) frame
        R = T[:3, :3] @ np.array([[0, 0, -1], [-1, 0, 0], [0, 1, 0]], float).T
        m = np.eye(4)
        m[:3, :3], m[:3, 3] = R, eye
        cam.camera.set_local_pose(sapien.Pose(m))
        u.scene.update_render()
        cam.capture()
        return cam.get_obs(rgb=True, depth=False, segmentation=False, position=False)["rgb"][0].cpu().numpy()

    def close(self):
        self.env.close()


# ----------------------------------------------------------------------------- driver
def _label(img: np.ndarray, text: str) -> np.ndarray:
    from PIL import Image, ImageDraw
    im = Image.fromarray(img)
    d = ImageDraw.Draw(im)
    d.rectangle([0, 0, 8 + 7 * len(text), 20], fill=(255, 255, 255))
    d.text((4, 4), text, fill=(20, 20, 20))
    return np.asarray(im)


def make_backend(traj: Trajectory, width: int, height: int, renderer: str = "auto"):
    if renderer not in ("auto", "pyrender", "sapien"):
        raise ValueError(f"unknown renderer {renderer!r}; valid: auto, pyrender, sapien")
    if renderer == "sapien" or (renderer == "auto" and _sapien_can_render() and _has_visual_meshes(traj.meta["hand"])):
        return SapienBackend(traj, width, height)
    return PyrenderBackend(traj, width, height)


def _has_visual_meshes(hand: str) -> bool:
    """Procedural hands have collision primitives only; SAPIEN would draw them invisible, pyrender
    draws their capsules."""
    from unicross.robots.hand import PROCEDURAL, load_hand
    return not load_hand(hand).urdf.startswith(PROCEDURAL)


def _sapien_can_render() -> bool:
    try:
        import torch
        return torch.cuda.is_available()
    except Exception:
        return False


def render_frames(traj: Trajectory, camera: str = "front", width: int = 640, height: int = 480,
                  frames: Optional[List[int]] = None, renderer: str = "auto", label: bool = True,
                  progress: bool = False) -> List[np.ndarray]:
    from tqdm import tqdm
    if camera not in CAMERAS:
        raise ValueError(f"unknown camera {camera!r}; valid: {list(CAMERAS)}")
    backend = make_backend(traj, width, height, renderer)
    modes = traj.meta.get("modes", [])
    out = []
    try:
        for t in tqdm(frames if frames is not None else range(len(traj)), desc="render", disable=not progress):
            img = backend.frame(t, camera)
            if label:
                phase = traj.labels[t] if traj.labels and traj.labels[t] else ""
                phase = "" if phase == (modes[int(traj.mode[t])] if modes else phase) else phase
                mode = modes[int(traj.mode[t])] if modes else str(int(traj.mode[t]))
                img = _label(img, f"{phase + ': ' if phase else ''}{mode}  step {int(traj.step[t])}")
            out.append(img)
    finally:
        backend.close()
    return out


def render(traj_path, out, camera: str = "front", width: int = 640, height: int = 480, fps: Optional[int] = None,
           renderer: str = "auto", every: int = 1, progress: bool = True) -> Path:
    """Render a trajectory file to ``out`` (.mp4, .gif or .png: one still of the last frame)."""
    traj = Trajectory.load(traj_path)
    out = Path(out)
    if out.suffix.lower() not in (".mp4", ".gif", ".png"):
        raise ValueError(f"output must end in .mp4, .gif or .png, got {out.name}")
    import imageio.v2 as imageio
    out.parent.mkdir(parents=True, exist_ok=True)
    fps = fps or traj.meta.get("control_freq", 20)
    if out.suffix.lower() == ".png":
        imageio.imwrite(out, render_frames(traj, camera, width, height, [len(traj) - 1], renderer)[0])
        return out
    idx = list(range(0, len(traj), max(1, every)))
    frames = render_frames(traj, camera, width, height, idx, renderer, progress=progress)
    if out.suffix.lower() == ".gif":
        imageio.mimsave(out, frames, duration=1000.0 / fps * max(1, every), loop=0)
    else:
        imageio.mimsave(out, frames, fps=fps / max(1, every), macro_block_size=1)
    return out
