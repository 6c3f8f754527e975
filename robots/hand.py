"""Hand descriptions as data, floating-URDF generation and ManiSkill agent registration.

A hand is described by one YAML file in ``configs/hands/`` (see ``allegro.yaml``). From it we
generate, at run time and into a cache directory (never into site-packages), a URDF in which
the original hand is mounted on six zero-initialised *virtual wrist joints*::

    root --wrist_tx--> . --wrist_ty--> . --wrist_tz--> . --wrist_rx--> . --wrist_ry--> . --wrist_rz--> hand_frame
    hand_frame --(fixed, -palm_point)--> <mount_link of the original hand> --> fingers

Conventions (documented once, used everywhere):

* The articulation root is fixed at the *root frame* r: the pose of the hand frame in the world
  at the start of the episode.
* ``wrist_tx, wrist_ty, wrist_tz`` translate the hand along the root-frame x, y, z axes
  (positive ``wrist_tz`` moves the hand towards +z of the root frame), in metres.
* ``wrist_rx, wrist_ry, wrist_rz`` then rotate it about x, y, z (intrinsic XYZ Euler angles), so
  the hand pose in the root frame is ``x_h^r = (tx, ty, tz)`` and
  ``R_h^r = Rx(rx) @ Ry(ry) @ Rz(rz)``. Virtual joint values and (x_h^r, Euler(q_h^r)) are the
  same numbers, which is what the action mapping's wrist reference needs.
* The *hand frame* h has its origin at the hand's palm point and the mount link's axes
  (Allegro: +x out of the palm, +z along the fingers).
* Hand links have gravity disabled: the virtual wrist acts like a gravity-compensated arm.
"""
from __future__ import annotations

import copy
import dataclasses
import hashlib
import os
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Dict, List

import numpy as np
import yaml

WRIST_JOINTS = ["wrist_tx", "wrist_ty", "wrist_tz", "wrist_rx", "wrist_ry", "wrist_rz"]
HAND_FRAME_LINK = "hand_frame"
from unicross.config import CONFIG_DIR


def cache_dir() -> Path:
    """Directory for generated artefacts (URDFs, object meshes). ``$UNICROSS_CACHE`` overrides."""
    d = Path(os.environ.get("UNICROSS_CACHE", Path.home() / ".cache" / "unicross"))
    d.mkdir(parents=True, exist_ok=True)
    return d


@dataclasses.dataclass
class HandSpec:
    """Everything a task needs to know about a hand. Loaded from ``configs/hands/<name>.yaml``."""

    name: str
    urdf: str
    mount_link: str
    palm_point: List[float]
    finger_joints: List[str]
    fingers: Dict[str, List[str]]
    init_pose_finger_order: List[str]
    init_poses: Dict[str, List[float]]
    contact_links: List[str]
    pd: Dict[str, Dict[str, float]]
    action_scale: Dict[str, float]
    wrist_limits: Dict[str, float]
    self_collision: bool = False
    object_scale: float = 1.0

    @property
    def joint_names(self) -> List[str]:
        """All actuated joints in action order: 6 virtual wrist joints, then the fingers."""
        return WRIST_JOINTS + list(self.finger_joints)

    @property
    def dof(self) -> int:
        return len(self.joint_names)

    @property
    def uid(self) -> str:
        return f"unicross_floating_{self.name}" + ("_selfcollide" if self.self_collision else "")

    def init_finger_qpos(self, category: str) -> np.ndarray:
        """Initial finger pose (theta0 for 'wrappable', theta1 for 'elongated') in
        ``finger_joints`` order, mapped from the paper's finger order by joint name."""
        if category not in self.init_poses:
            raise ValueError(f"hand {self.name!r} has no initial pose for category {category!r}; "
                             f"valid: {sorted(self.init_poses)}")
        values = list(self.init_poses[category])
        by_name = {}
        for finger in self.init_pose_finger_order:
            for joint in self.fingers[finger]:
                by_name[joint] = values.pop(0)
        if values:
            raise ValueError(f"hand {self.name!r}: initial pose {category!r} has too many values")
        return np.array([by_name[j] for j in self.finger_joints], dtype=np.float32)

    def action_scales(self) -> np.ndarray:
        s = self.action_scale
        return np.array([s["wrist_translation"]] * 3 + [s["wrist_rotation"]] * 3
                        + [s["finger"]] * len(self.finger_joints), dtype=np.float32)

    def resolve_urdf(self) -> Path:
        if self.urdf.startswith("mani_skill://"):
            from mani_skill import PACKAGE_ASSET_DIR
            return Path(PACKAGE_ASSET_DIR) / self.urdf[len("mani_skill://"):]
        p = Path(self.urdf)
        return p if p.is_absolute() else (CONFIG_DIR / "hands" / p).resolve()


_REGISTERED: Dict[str, HandSpec] = {}


def available_hands() -> List[str]:
    return sorted({p.stem for p in (CONFIG_DIR / "hands").glob("*.yaml")} | set(_REGISTERED))


def register_hand(description) -> HandSpec:
    """Add a hand at run time from a YAML path, a dict or a HandSpec (same fields as
    ``configs/hands/allegro.yaml``); tasks, training and evaluation then accept its name."""
    if isinstance(description, HandSpec):
        spec = description
    else:
        if isinstance(description, (str, Path)):
            with open(description) as f:
                description = yaml.safe_load(f)
        try:
            spec = HandSpec(**description)
        except TypeError as e:
            raise ValueError(f"invalid hand description: {e}") from None
    if spec.urdf and not Path(spec.urdf).is_absolute() and not spec.urdf.startswith("mani_skill://"):
        raise ValueError("a registered hand needs an absolute urdf path or a mani_skill:// one")
    _REGISTERED[spec.name] = spec
    return spec


def load_hand(name: str) -> HandSpec:
    """A hand description by name: registered at run time, or ``configs/hands/<name>.yaml``."""
    if name in _REGISTERED:
        return copy.deepcopy(_REGISTERED[name])
    path = CONFIG_DIR / "hands" / f"{name}.yaml"
    if not path.exists():
        raise ValueError(f"unknown hand {name!r}; valid hands: {available_hands()}")
    with open(path) as f:
        data = yaml.safe_load(f)
    return HandSpec(**data)


# ----------------------------------------------------------------------------- URDF generation
def _virtual_link(name: str) -> ET.Element:
    link = ET.Element("link", name=name)
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", xyz="0 0 0", rpy="0 0 0")
    ET.SubElement(inertial, "mass", value="0.01")
    ET.SubElement(inertial, "inertia", ixx="1e-6", iyy="1e-6", izz="1e-6", ixy="0", ixz="0", iyz="0")
    return link


def build_floating_urdf(spec: HandSpec) -> Path:
    """Write the floating-hand URDF into the cache and return its path (content-addressed)."""
    src = spec.resolve_urdf()
    if not src.exists():
        raise FileNotFoundError(f"hand {spec.name!r}: URDF not found at {src}")
    tree = ET.parse(src)
    robot = tree.getroot()
    for mesh in robot.iter("mesh"):  # absolute mesh paths: the URDF lives elsewhere
        fn = mesh.get("filename")
        if fn and not fn.startswith(("/", "package://")):
            mesh.set("filename", str((src.parent / fn).resolve()))
    joints = robot.findall("joint")
    names = {j.get("name") for j in joints}
    for j in spec.finger_joints:
        if j not in names:
            raise ValueError(f"hand {spec.name!r}: finger joint {j!r} not in {src}")
    old_children = list(robot)
    for c in old_children:
        robot.remove(c)
    t, r = spec.wrist_limits["translation"], spec.wrist_limits["rotation"]
    chain = ["root", "wrist_tx_link", "wrist_ty_link", "wrist_tz_link", "wrist_rx_link", "wrist_ry_link",
             HAND_FRAME_LINK]
    axes = ["1 0 0", "0 1 0", "0 0 1", "1 0 0", "0 1 0", "0 0 1"]
    for name in chain:
        robot.append(_virtual_link(name))
    for i, jname in enumerate(WRIST_JOINTS):
        kind = "prismatic" if i < 3 else "revolute"
        lim = t if i < 3 else r
        j = ET.SubElement(robot, "joint", name=jname, type=kind)
        ET.SubElement(j, "parent", link=chain[i])
        ET.SubElement(j, "child", link=chain[i + 1])
        ET.SubElement(j, "origin", xyz="0 0 0", rpy="0 0 0")
        ET.SubElement(j, "axis", xyz=axes[i])
        ET.SubElement(j, "limit", lower=str(-lim), upper=str(lim), effort="1000", velocity="10")
    mount = ET.SubElement(robot, "joint", name="hand_mount", type="fixed")
    ET.SubElement(mount, "parent", link=HAND_FRAME_LINK)
    ET.SubElement(mount, "child", link=spec.mount_link)
    pp = -np.asarray(spec.palm_point, dtype=float)
    ET.SubElement(mount, "origin", xyz=" ".join(f"{v:.6f}" for v in pp), rpy="0 0 0")
    for c in old_children:
        robot.append(c)
    text = ET.tostring(robot, encoding="unicode")
    digest = hashlib.sha1(text.encode()).hexdigest()[:12]
    out = cache_dir() / "robots" / f"{spec.name}_floating_{digest}.urdf"
    if not out.exists():
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = out.with_suffix(".tmp")
        tmp.write_text('<?xml version="1.0"?>\n' + text)
        os.replace(tmp, out)
    return out


# ----------------------------------------------------------------------------- agent registration
_AGENT_CLASSES: Dict[str, type] = {}


def register_hand_agent(spec: HandSpec) -> type:
    """Create (once) and register a ManiSkill agent class for the floating hand ``spec``.

    The agent's only controller, ``pd_joint_pos``, takes absolute joint targets for all
    ``spec.dof`` joints; the tasks map normalised actions to those targets.
    """
    if spec.uid in _AGENT_CLASSES:
        return _AGENT_CLASSES[spec.uid]
    from mani_skill.agents.base_agent import BaseAgent
    from mani_skill.agents.controllers import PDJointPosControllerConfig
    from mani_skill.agents.registration import REGISTERED_AGENTS, register_agent

    urdf_path = build_floating_urdf(spec)
    pd = spec.pd
    n_f = len(spec.finger_joints)
    stiffness = [pd["wrist_translation"]["stiffness"]] * 3 + [pd["wrist_rotation"]["stiffness"]] * 3 \
        + [pd["finger"]["stiffness"]] * n_f
    damping = [pd["wrist_translation"]["damping"]] * 3 + [pd["wrist_rotation"]["damping"]] * 3 \
        + [pd["finger"]["damping"]] * n_f
    force_limit = [pd["wrist_translation"]["force_limit"]] * 3 + [pd["wrist_rotation"]["force_limit"]] * 3 \
        + [pd["finger"]["force_limit"]] * n_f
    joint_names = spec.joint_names

    class FloatingHand(BaseAgent):
        uid = spec.uid
        disable_self_collisions = not spec.self_collision
        hand_spec = spec

        def __init__(self, *args, **kwargs):
            self.urdf_path = str(urdf_path)
            super().__init__(*args, **kwargs)

        @property
        def _controller_configs(self):
            return dict(pd_joint_pos=PDJointPosControllerConfig(
                joint_names, None, None, stiffness, damping, force_limit, normalize_action=False))

        def _after_loading_articulation(self):
            for link in self.robot.links:
                for body in link._objs:
                    body.disable_gravity = True

    FloatingHand.__name__ = f"FloatingHand_{spec.name}"
    FloatingHand.urdf_path = str(urdf_path)
    if spec.uid in REGISTERED_AGENTS:
        del REGISTERED_AGENTS[spec.uid]
    register_agent()(FloatingHand)
    _AGENT_CLASSES[spec.uid] = FloatingHand
    return FloatingHand
