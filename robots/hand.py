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
* The *hand frame* h has its origin at the hand's palm point, +x out of the palm (palm normal),
  +z along the fingers and +y = z x x (towards the index/thumb side of a right hand), for every
  hand: a description gives ``palm_normal`` and ``finger_direction`` in its mount-link frame
  and the fixed mount joint carries the rotation.
* Hand links have gravity disabled: the virtual wrist acts like a gravity-compensated arm.
* Coupled (mimic) joints, e.g. the Ability/Inspire distal joints, are not actions: each follower
  gets a drive target ``multiplier * target(master) + offset`` (chains are resolved to an actuated
  master), written next to the actuated targets every control step.
* ``urdf: procedural://<name>`` builds the hand from code (:mod:`unicross.robots.procedural`),
  e.g. the MANO-layout human hand and Sharpa Wave from their kinematic facts.
"""
from __future__ import annotations

import copy
import dataclasses
import hashlib
import os
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Dict, List, Optional, Tuple

import numpy as np
import yaml

PROCEDURAL = "procedural://"
WRIST_JOINTS = ["wrist_tx", "wrist_ty", "wrist_tz", "wrist_rx", "wrist_ry", "wrist_rz"]
HAND_FRAME_LINK = "hand_frame"
from unicross.config import CONFIG_DIR, atomic_write


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
    # hand-frame axes in the mount-link frame (defaults: the mount link already follows the convention)
    palm_normal: List[float] = dataclasses.field(default_factory=lambda: [1.0, 0.0, 0.0])
    finger_direction: List[float] = dataclasses.field(default_factory=lambda: [0.0, 0.0, 1.0])
    # follower joint -> {joint: leader, multiplier, offset}; followers are driven, not actions
    mimic: Dict[str, Dict] = dataclasses.field(default_factory=dict)
    # scripted grasp synthesiser: joint -> closing increment (rad); None = flex every joint but
    # the first of each finger by 0.7 rad (Allegro-like four-joint fingers)
    closing_delta: Optional[Dict[str, float]] = None
    # scripted finger gaits (unicross.gaits): finger -> [abduction, proximal flexion, distal flexion...] joints;
    # a finger not named moves its joints in order (a four-joint finger as Allegro's)
    gait_joints: Optional[Dict[str, List[str]]] = None
    description: str = ""

    def __post_init__(self):
        dup = {j for j in self.finger_joints if self.finger_joints.count(j) > 1}
        if dup:
            raise ValueError(f"hand {self.name!r}: finger joints listed twice: {sorted(dup)}")
        listed = [j for js in self.fingers.values() for j in js]
        if sorted(listed) != sorted(self.finger_joints):
            raise ValueError(f"hand {self.name!r}: `fingers` must partition `finger_joints` "
                             f"(missing {sorted(set(self.finger_joints) - set(listed))}, "
                             f"extra {sorted(set(listed) - set(self.finger_joints))})")
        bad = [f for f in self.init_pose_finger_order if f not in self.fingers]
        if bad:
            raise ValueError(f"hand {self.name!r}: init_pose_finger_order names unknown fingers {bad}")
        for cat, values in self.init_poses.items():
            if len(values) != len(self.finger_joints):
                raise ValueError(f"hand {self.name!r}: initial pose {cat!r} has {len(values)} values, "
                                 f"expected {len(self.finger_joints)}")
        for f, m in self.mimic.items():
            if f in self.finger_joints or set(m) - {"joint", "multiplier", "offset"} or "joint" not in m:
                raise ValueError(f"hand {self.name!r}: bad mimic entry {f!r}: {m} (a follower is not a "
                                 f"finger joint; keys: joint, multiplier, offset)")
        for finger, js in (self.gait_joints or {}).items():
            if finger not in self.fingers or len(js) < 3 or not set(js) <= set(self.fingers[finger]) \
                    or len(set(js)) != len(js):
                raise ValueError(f"hand {self.name!r}: gait_joints[{finger!r}] = {js} must name at least three "
                                 f"distinct joints of that finger (abduction, proximal, distal...)")
        self.resolved_mimic()
        self.mount_rotation()

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

    def resolved_mimic(self) -> List[Tuple[str, str, float, float]]:
        """(follower, actuated finger joint, multiplier, offset) per mimic follower, with chains
        (a follower of a follower) composed down to an actuated joint."""
        out = []
        for follower in self.mimic:
            mult, off, j, seen = 1.0, 0.0, follower, {follower}
            while j in self.mimic:
                m = self.mimic[j]
                k, o = float(m.get("multiplier", 1.0)), float(m.get("offset", 0.0))
                mult, off = mult * k, off * k + o
                j = m["joint"]
                if j in seen:
                    raise ValueError(f"hand {self.name!r}: mimic cycle through {j!r}")
                seen.add(j)
            if j not in self.finger_joints:
                raise ValueError(f"hand {self.name!r}: mimic follower {follower!r} leads to {j!r}, "
                                 f"which is not a finger joint")
            out.append((follower, j, mult, off))
        return out

    def mount_rotation(self) -> np.ndarray:
        """3x3 matrix whose columns are the hand-frame axes x, y, z in the mount-link frame."""
        x = np.asarray(self.palm_normal, float)
        z = np.asarray(self.finger_direction, float)
        if x.shape != (3,) or z.shape != (3,) or np.linalg.norm(x) < 1e-9 or np.linalg.norm(z) < 1e-9:
            raise ValueError(f"hand {self.name!r}: palm_normal and finger_direction must be non-zero 3-vectors")
        x, z = x / np.linalg.norm(x), z / np.linalg.norm(z)
        if abs(float(x @ z)) > 1e-3:
            raise ValueError(f"hand {self.name!r}: palm_normal must be perpendicular to finger_direction")
        return np.stack([x, np.cross(z, x), z], axis=1)

    def closing_deltas(self) -> np.ndarray:
        """Closing increment per finger joint (``finger_joints`` order) for the scripted grasp."""
        if self.closing_delta is not None:
            unknown = set(self.closing_delta) - set(self.finger_joints)
            if unknown:
                raise ValueError(f"hand {self.name!r}: closing_delta names unknown joints {sorted(unknown)}")
            return np.array([float(self.closing_delta.get(j, 0.0)) for j in self.finger_joints], np.float32)
        first = {js[0] for js in self.fingers.values()}
        return np.array([0.0 if j in first else 0.7 for j in self.finger_joints], np.float32)

    def action_scales(self) -> np.ndarray:
        s = self.action_scale
        return np.array([s["wrist_translation"]] * 3 + [s["wrist_rotation"]] * 3
                        + [s["finger"]] * len(self.finger_joints), dtype=np.float32)

    def resolve_urdf(self) -> Path:
        if self.urdf.startswith("mani_skill://"):
            from mani_skill import PACKAGE_ASSET_DIR
            return Path(PACKAGE_ASSET_DIR) / self.urdf[len("mani_skill://"):]
        if self.urdf.startswith(PROCEDURAL):
            from unicross.robots.procedural import write_procedural_urdf
            return write_procedural_urdf(self.urdf[len(PROCEDURAL):], cache_dir() / "robots")
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
        spec = _spec_from_dict(description)
    if spec.urdf and not Path(spec.urdf).is_absolute() and not spec.urdf.startswith(("mani_skill://", PROCEDURAL)):
        raise ValueError("a registered hand needs an absolute urdf path, a mani_skill:// or a procedural:// one")
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
    return _spec_from_dict(data, source=path)


def _spec_from_dict(data: dict, source=None) -> HandSpec:
    try:
        return HandSpec(**data)
    except TypeError as e:
        raise ValueError(f"invalid hand description{f' {source}' if source else ''}: {e}") from None


# ----------------------------------------------------------------------------- URDF generation
def _virtual_link(name: str) -> ET.Element:
    link = ET.Element("link", name=name)
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", xyz="0 0 0", rpy="0 0 0")
    ET.SubElement(inertial, "mass", value="0.01")
    ET.SubElement(inertial, "inertia", ixx="1e-6", iyy="1e-6", izz="1e-6", ixy="0", ixz="0", iyz="0")
    return link


def matrix_to_rpy(R: np.ndarray) -> np.ndarray:
    """URDF roll-pitch-yaw (R = Rz(yaw) Ry(pitch) Rx(roll)) of a rotation matrix."""
    pitch = np.arcsin(np.clip(-R[2, 0], -1.0, 1.0))
    if abs(np.cos(pitch)) > 1e-9:
        return np.array([np.arctan2(R[2, 1], R[2, 2]), pitch, np.arctan2(R[1, 0], R[0, 0])])
    return np.array([0.0, pitch, np.arctan2(-R[0, 1], R[1, 1])])  # gimbal lock: roll folded into yaw


def _keep_subtree(robot: ET.Element, mount_link: str, src, hand: str) -> None:
    """Drop every link and joint that is not below ``mount_link`` (e.g. a shipped hand's own
    wrist joints, which the virtual wrist replaces)."""
    links = {l.get("name") for l in robot.findall("link")}
    if mount_link not in links:
        raise ValueError(f"hand {hand!r}: mount link {mount_link!r} not in {src}")
    children: Dict[str, List[ET.Element]] = {}
    for j in robot.findall("joint"):
        children.setdefault(j.find("parent").get("link"), []).append(j)
    keep_links, keep_joints, stack = {mount_link}, set(), [mount_link]
    while stack:
        for j in children.get(stack.pop(), []):
            keep_joints.add(id(j))
            child = j.find("child").get("link")
            keep_links.add(child)
            stack.append(child)
    for el in list(robot):
        if (el.tag == "link" and el.get("name") not in keep_links) or (el.tag == "joint" and id(el) not in keep_joints):
            robot.remove(el)


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
    _keep_subtree(robot, spec.mount_link, src, spec.name)
    joints = robot.findall("joint")
    names = {j.get("name") for j in joints}
    for j in list(spec.finger_joints) + list(spec.mimic):
        if j not in names:
            raise ValueError(f"hand {spec.name!r}: joint {j!r} not below {spec.mount_link!r} in {src}")
    loose = sorted(j.get("name") for j in joints if j.get("type") != "fixed"
                   and j.get("name") not in spec.finger_joints and j.get("name") not in spec.mimic)
    if loose:
        raise ValueError(f"hand {spec.name!r}: joints {loose} are neither finger joints nor mimic "
                         f"followers (they would have no drive)")
    for j in joints:  # couplings are drive targets (see module docstring), not PhysX tendons
        for m in j.findall("mimic"):
            j.remove(m)
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
    R_hm = spec.mount_rotation().T  # mount-link axes in the hand frame
    pp = -R_hm @ np.asarray(spec.palm_point, dtype=float)
    rpy = matrix_to_rpy(R_hm)
    ET.SubElement(mount, "origin", xyz=" ".join(f"{v:.6f}" for v in pp), rpy=" ".join(f"{v:.9f}" for v in rpy))
    for c in old_children:
        robot.append(c)
    text = ET.tostring(robot, encoding="unicode")
    digest = hashlib.sha1(text.encode()).hexdigest()[:12]
    out = cache_dir() / "robots" / f"{spec.name}_floating_{digest}.urdf"
    if not out.exists():
        atomic_write(out, lambda tmp: tmp.write_text('<?xml version="1.0"?>\n' + text))
    return out


def finger_drive_gains(spec: HandSpec, urdf_path=None) -> Dict[str, Tuple[float, float, float]]:
    """(stiffness, damping, force limit) of every finger joint and mimic follower.
    ``pd.finger.force_limit: urdf`` takes each joint's ``<limit effort>`` from the hand's URDF."""
    pd = spec.pd["finger"]
    names = list(spec.finger_joints) + list(spec.mimic)
    limit = pd["force_limit"]
    if limit == "urdf":
        root = ET.parse(urdf_path or build_floating_urdf(spec)).getroot()
        effort = {j.get("name"): float(j.find("limit").get("effort")) for j in root.findall("joint")
                  if j.find("limit") is not None and j.find("limit").get("effort") is not None}
        missing = [n for n in names if n not in effort]
        if missing:
            raise ValueError(f"hand {spec.name!r}: force_limit 'urdf' but no effort for joints {missing}")
        return {n: (float(pd["stiffness"]), float(pd["damping"]), effort[n]) for n in names}
    return {n: (float(pd["stiffness"]), float(pd["damping"]), float(limit)) for n in names}


# ----------------------------------------------------------------------------- agent registration
_AGENT_CLASSES: Dict[str, type] = {}


def register_hand_agent(spec: HandSpec) -> type:
    """Create (once) and register a ManiSkill agent class for the floating hand ``spec``.

    The agent's only controller, ``pd_joint_pos``, sets up the PD drives of the ``spec.dof``
    actuated joints and of the mimic followers; the tasks write the drive targets themselves.
    """
    if spec.uid in _AGENT_CLASSES:
        return _AGENT_CLASSES[spec.uid]
    from mani_skill.agents.base_agent import BaseAgent
    from mani_skill.agents.controllers import PDJointPosControllerConfig
    from mani_skill.agents.registration import REGISTERED_AGENTS, register_agent

    urdf_path = build_floating_urdf(spec)
    joint_names = spec.joint_names + list(spec.mimic)
    gains = finger_drive_gains(spec, urdf_path)
    stiffness = [spec.pd["wrist_translation"]["stiffness"]] * 3 + [spec.pd["wrist_rotation"]["stiffness"]] * 3 \
        + [gains[j][0] for j in joint_names[6:]]
    damping = [spec.pd["wrist_translation"]["damping"]] * 3 + [spec.pd["wrist_rotation"]["damping"]] * 3 \
        + [gains[j][1] for j in joint_names[6:]]
    force_limit = [spec.pd["wrist_translation"]["force_limit"]] * 3 + [spec.pd["wrist_rotation"]["force_limit"]] * 3 \
        + [gains[j][2] for j in joint_names[6:]]

    class FloatingHand(BaseAgent):
        uid = spec.uid
        disable_self_collisions = not spec.self_collision
        hand_spec = spec
        finger_gains = gains  # (stiffness, damping, force limit) per finger joint and follower

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
