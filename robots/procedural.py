"""Hands built from code: URDFs generated from kinematic facts, with primitive collision shapes.

``urdf: procedural://<name>`` in a hand description selects a generator from ``GENERATORS``.
Each generator returns a :class:`Hand` (links with masses and primitive shapes, joints with
frames, axes, limits and efforts); :func:`urdf_text` writes it as URDF with collision shapes only (no
visuals: SAPIEN would create render materials for them, which fails without a rendering device);
:mod:`unicross.render` draws the collision primitives of links that have no visual.

* ``mano``: a right human hand in the MANO layout (mean shape), 20 finger DoF following CPF's
  anatomical joint definitions (finger: MCP abduction + flexion, PIP, DIP; thumb: CMC 2, MCP, IP).
  Joint offsets, capsule sizes and link masses are those of ``shared/reference/mano_kinematics.md``
  (read from GraspXL's simulatable MANO hand); the MANO mesh itself is not used or shipped.
* ``sharpa_wave``: Sharpa Wave (right), 22 finger DoF, joint frames/axes/limits/efforts/masses of
  ``shared/reference/sharpa_wave_kinematics.md``; links are capsules along each phalanx and a
  box palm, sized from the joint offsets (the original STL meshes are not reproduced).

Inertias are those of the link's first primitive as a solid body of the link's mass (the hand
floats on PD-driven virtual joints with gravity off, so only their order of magnitude matters).
"""
from __future__ import annotations

import dataclasses
import hashlib
import math
from pathlib import Path
from typing import Callable, Dict, List, Optional, Sequence, Tuple
import xml.etree.ElementTree as ET

import numpy as np

from unicross.config import atomic_write

Vec = Sequence[float]


@dataclasses.dataclass
class Shape:
    kind: str                    # "box" (size = full extents), "capsule" (radius, length along z), "sphere"
    size: Tuple[float, ...]
    xyz: Vec = (0.0, 0.0, 0.0)
    rpy: Vec = (0.0, 0.0, 0.0)


@dataclasses.dataclass
class Link:
    name: str
    mass: float
    shapes: List[Shape] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class Joint:
    name: str
    parent: str
    child: str
    xyz: Vec = (0.0, 0.0, 0.0)
    rpy: Vec = (0.0, 0.0, 0.0)
    axis: Vec = (0.0, 0.0, 1.0)
    limits: Optional[Tuple[float, float]] = None  # None: fixed joint
    effort: float = 1.0


@dataclasses.dataclass
class Hand:
    name: str
    links: List[Link]
    joints: List[Joint]


def capsule_between(a: Vec, b: Vec, radius: float) -> Shape:
    """A capsule whose segment runs from point ``a`` to point ``b`` (link frame)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    length = float(np.linalg.norm(d))
    z = d / length
    pitch = math.atan2(math.hypot(z[0], z[1]), z[2])  # rotate +z onto d: yaw about z after pitch about y
    yaw = math.atan2(z[1], z[0])
    return Shape("capsule", (radius, length), tuple((a + b) / 2), (0.0, pitch, yaw))


def _inertia(mass: float, shape: Optional[Shape]) -> Tuple[float, float, float]:
    if shape is None:
        return (1e-7, 1e-7, 1e-7)
    if shape.kind == "box":
        x, y, z = shape.size
        return (mass * (y * y + z * z) / 12, mass * (x * x + z * z) / 12, mass * (x * x + y * y) / 12)
    if shape.kind == "capsule":  # as a cylinder of the full length
        r, l = shape.size
        l = l + 2 * r
        side = mass * (3 * r * r + l * l) / 12
        return (side, side, mass * r * r / 2)
    r = shape.size[0]
    return (0.4 * mass * r * r,) * 3


def _fmt(v: Vec) -> str:
    return " ".join(f"{float(x):.9g}" for x in v)


def _geometry(parent: ET.Element, s: Shape) -> None:
    g = ET.SubElement(parent, "geometry")
    if s.kind == "box":
        ET.SubElement(g, "box", size=_fmt(s.size))
    elif s.kind == "capsule":
        ET.SubElement(g, "capsule", radius=f"{s.size[0]:.9g}", length=f"{s.size[1]:.9g}")
    elif s.kind == "sphere":
        ET.SubElement(g, "sphere", radius=f"{s.size[0]:.9g}")
    else:
        raise ValueError(f"unknown primitive {s.kind!r}")


def urdf_text(hand: Hand) -> str:
    robot = ET.Element("robot", name=hand.name)
    for link in hand.links:
        el = ET.SubElement(robot, "link", name=link.name)
        inertial = ET.SubElement(el, "inertial")
        first = link.shapes[0] if link.shapes else None
        com = first.xyz if first is not None else (0.0, 0.0, 0.0)
        rpy = first.rpy if first is not None else (0.0, 0.0, 0.0)
        ET.SubElement(inertial, "origin", xyz=_fmt(com), rpy=_fmt(rpy))
        ET.SubElement(inertial, "mass", value=f"{link.mass:.9g}")
        ixx, iyy, izz = _inertia(link.mass, first)
        ET.SubElement(inertial, "inertia", ixx=f"{ixx:.6g}", iyy=f"{iyy:.6g}", izz=f"{izz:.6g}",
                      ixy="0", ixz="0", iyz="0")
        for s in link.shapes:  # collision only: SAPIEN makes render materials for primitive visuals
            v = ET.SubElement(el, "collision")
            ET.SubElement(v, "origin", xyz=_fmt(s.xyz), rpy=_fmt(s.rpy))
            _geometry(v, s)
    for j in hand.joints:
        el = ET.SubElement(robot, "joint", name=j.name, type="fixed" if j.limits is None else "revolute")
        ET.SubElement(el, "parent", link=j.parent)
        ET.SubElement(el, "child", link=j.child)
        ET.SubElement(el, "origin", xyz=_fmt(j.xyz), rpy=_fmt(j.rpy))
        if j.limits is not None:
            ET.SubElement(el, "axis", xyz=_fmt(j.axis))
            ET.SubElement(el, "limit", lower=f"{j.limits[0]:.9g}", upper=f"{j.limits[1]:.9g}",
                          effort=f"{j.effort:.9g}", velocity="10")
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode")


# ----------------------------------------------------------------------------- MANO layout
# Offsets of each joint from its parent (wrist frame axes; x points from the fingers to the
# wrist, -y is the palm normal, +z the thumb side), capsule (origin, rpy, length, radius) and
# link masses, from shared/reference/mano_kinematics.md.
MANO_OFFSETS = {
    "index": [(-0.08809725940227509, -0.005200356710702181, 0.02068599313497543),
              (-0.03267890214920044, 0.004009355790913105, 0.002217065542936325),
              (-0.02215591073036194, -0.001298423390835524, -0.000114118680357933),
              (-0.025482177734375, 0.001184116583317518, -0.0005013830959796906)],
    "middle": [(-0.09466045349836349, -0.001478962600231171, -0.003357539651915431),
               (-0.03118266724050045, 0.001861328259110451, -0.005594509653747082),
               (-0.02290463633835316, -0.00125210452824831, -0.003944513387978077),
               (-0.0256921648979187, 0.003846850246191025, -0.004136247560381889)],
    "pinky": [(-0.06878697872161865, -0.009940328076481819, -0.04320933669805527),
              (-0.01701441034674644, 6.182515062391758e-05, -0.01249878108501434),
              (-0.01586690172553062, -0.0006911561358720064, -0.0103319026529789),
              (-0.01709342189133167, 0.001548676285892725, -0.01031537726521492)],
    "ring": [(-0.08173556625843048, -0.003957420587539673, -0.02667319029569626),
             (-0.02831427380442619, 0.002067007124423981, -0.005098538473248482),
             (-0.02352051809430122, -0.001688111573457718, -0.007633816450834274),
             (-0.02443568781018257, 0.003858924377709627, -0.007340483367443085)],
    "thumb": [(-0.02408971637487411, -0.01552233379334211, 0.02581284381449223),
              (-0.01963324472308159, 0.0008912868797779083, 0.0236995555460453),
              (-0.02221773564815521, -0.005432971753180027, 0.01452412083745003),
              (-0.02601354569196701, -0.002678442746400833, 0.02388214319944382)],
}
MANO_CAPSULES = {  # per finger, per phalanx 1..3: (origin xyz, rpy, length, radius)
    "index": [((-0.0118830343708396, 0.001457922742702067, 0.0008061919361352921), (-1.065673404150012, -1.431506141451089, 0.9477048864768798), 0.02399849852919578, 0.009),
              ((-0.007334427908062935, -0.0004298262647353113, -3.777751408051699e-05), (1.658461261310608, -1.512034214827133, -1.5997737489094), 0.01469421602785587, 0.0075),
              ((-0.009001294411288496, -0.0006414405166041191, -0.0001771079735335346), (1.840193960081717, -1.497003187126881, -1.76835496522512), 0.0180517161787265, 0.0075)],
    "middle": [((-0.0111696794629097, 0.0006667306879535317, -0.002003961941227317), (-2.820406600974239, -1.383922349862802, 2.755488033918114), 0.02273518180847168, 0.009),
               ((-0.007762070745229721, -0.0004243212752044201, -0.00133674219250679), (2.834223256819131, -1.392042172086062, -2.77494923392455), 0.01577550947666168, 0.0075),
               ((-0.009145713945442134, 0.0003014557215035537, -0.001472391958602528), (-2.939644762229884, -1.407919909220686, 2.904061101940813), 0.01853676316983516, 0.0075)],
    "pinky": [((-0.004880589433014393, 1.773456642695237e-05, -0.003585279919207096), (-3.13664619965706, -0.9372186196136476, 3.131821312881724), 0.01211192792654038, 0.009),
              ((-0.004793046973645687, -0.0002087832690449432, -0.003121043555438519), (3.074796837859433, -0.9925842493150498, -3.018349175930415), 0.01144688606262207, 0.0075),
              ((-0.005771451704418715, -0.0004900273787599806, -0.00348290132177909), (3.001814974863856, -1.023483359517321, -2.893594779193235), 0.01351745289995458, 0.0065)],
    "ring": [((-0.009739752858877182, 0.000711024331394583, -0.001753832912072539), (-2.756429740384719, -1.378882821128404, 2.677062098469931), 0.01984381636977196, 0.009),
             ((-0.008201702497899532, -0.0005886515136808157, -0.002661943435668945), (2.923959085930092, -1.249885231202113, -2.840996889674495), 0.01728587441146374, 0.0075),
             ((-0.008628424416764247, 0.0003032926320860706, -0.002591979665581778), (-3.025110379404621, -1.277093683239337, 2.984813522576495), 0.01802887161452769, 0.0075)],
    "thumb": [((-0.006628209725022316, 0.0003008996718563139, 0.008001001551747322), (-0.03759002942324141, -0.6914858879290118, 0.01354175456813378), 0.02078843280673027, 0.01),
              ((-0.007008775603026152, -0.00171387754380703, 0.004581758752465248), (0.3579510780566544, -0.9614433161852158, -0.1881438544702494), 0.01709418907761574, 0.01),
              ((-0.01142392981416996, -0.002460023821868162, 0.007691998220689819), (0.3095359939145883, -0.9554413808442996, -0.1611940556331888), 0.02798033067927078, 0.01)],
}
MANO_MASSES = {"index": (0.00886, 0.00430, 0.00310), "middle": (0.01041, 0.00413, 0.00302),
               "pinky": (0.00430, 0.00278, 0.00157), "ring": (0.00757, 0.00503, 0.00288),
               "thumb": (0.01389, 0.00818, 0.00748)}
MANO_PALM = [Shape("box", (0.0878, 0.027, 0.07), (-0.03922105953097343, -0.003785171080380678, -0.0006308349594473838),
                   (0.006844884579535027, -0.1419415805103208, 0.09621061312114154)),
             Shape("capsule", (0.015, 0.0235689027607441), (-0.0144538301974535, -0.009313400834798813, 0.01548770722001791),
                   (0.541405353260723, -0.6746053143028581, -0.1940404583427586))]
MANO_PALM_MASS = 0.15  # kg; not in the reference (chosen: a light palm, hand links have gravity off)
# CPF-style joint ranges (rad). The reference's per-axis ranges belong to 3-DoF ball joints and do
# not contain the paper's initial poses (e.g. index abduction 0.7), so the ranges are chosen to
# contain theta0/theta1 with a margin.
MANO_FINGER_LIMITS = dict(mcp_abd=(-0.8, 0.8), mcp_flex=(-0.3, 1.6), pip=(-0.1, 1.7), dip=(-0.1, 1.3))
MANO_THUMB_LIMITS = dict(cmc_abd=(-0.3, 1.9), cmc_flex=(-0.6, 1.2), mcp=(-0.5, 1.2), ip=(-0.3, 1.5))


def _unit(v) -> Tuple[float, float, float]:
    v = np.asarray(v, float)
    return tuple(v / np.linalg.norm(v))


def mano_hand() -> Hand:
    """Right MANO-layout hand, 20 finger DoF (CPF definitions). Mount link: ``wrist``.

    Fingers (index, middle, ring, pinky): ``<f>_mcp_abd`` about the palm normal (+: towards the
    thumb side), ``<f>_mcp_flex``, ``<f>_pip``, ``<f>_dip`` about the wrist z axis (+: flexion,
    towards the palm). Thumb: ``thumb_cmc_abd`` about the wrist x axis (+: palmar abduction, the
    thumb swings out in front of the palm), ``thumb_cmc_flex`` about the palm normal (+: towards
    the fingers), ``thumb_mcp`` and ``thumb_ip`` about the axis perpendicular to the phalanx and the
    palm normal (+: the thumb curls towards its pad).
    """
    links = [Link("wrist", MANO_PALM_MASS, list(MANO_PALM))]
    joints: List[Joint] = []
    palm_normal = np.array([0.0, -1.0, 0.0])
    for f in ("index", "middle", "ring", "pinky", "thumb"):
        off, caps, mass = MANO_OFFSETS[f], MANO_CAPSULES[f], MANO_MASSES[f]
        shapes = [Shape("capsule", (r, l), xyz, rpy) for xyz, rpy, l, r in caps]
        if f == "thumb":
            names = ["thumb_cmc_abd", "thumb_cmc_flex", "thumb_mcp", "thumb_ip"]
            lims = list(MANO_THUMB_LIMITS.values())
            curl = [_unit(np.cross(palm_normal, -np.asarray(off[k + 1])))  # tip velocity: towards -y
                    for k in (1, 2)]
            axes = [(1.0, 0.0, 0.0), (0.0, -1.0, 0.0), curl[0], curl[1]]
        else:
            names = [f"{f}_mcp_abd", f"{f}_mcp_flex", f"{f}_pip", f"{f}_dip"]
            lims = list(MANO_FINGER_LIMITS.values())
            axes = [(0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, 1.0), (0.0, 0.0, 1.0)]
        # two-DoF base joint: a massless-ish link between the two axes
        links.append(Link(f"{f}0", 1e-4))
        links += [Link(f"{f}{k + 1}", mass[k], [shapes[k]]) for k in range(3)]
        links.append(Link(f"{f}_tip", 1e-6))
        chain = ["wrist", f"{f}0", f"{f}1", f"{f}2", f"{f}3"]
        origins = [off[0], (0.0, 0.0, 0.0), off[1], off[2]]
        for k in range(4):
            joints.append(Joint(names[k], chain[k], chain[k + 1], origins[k], axis=axes[k], limits=lims[k],
                                effort=1.0))
        joints.append(Joint(f"{f}_tip_joint", f"{f}3", f"{f}_tip", off[3]))
    return Hand("mano_right", links, joints)


# ----------------------------------------------------------------------------- Sharpa Wave
# (name, parent, child, xyz, rpy, lower, upper, effort, child mass) from
# shared/reference/sharpa_wave_kinematics.md; all joints rotate about their z axis.
SHARPA_JOINTS = [
    ("thumb_CMC_FE", "C_MC", "thumb_CMC_VL", (0.01, 0.026, 0.0214), (3.1416, 0, 1.5708), -0.1745, 1.9199, 3.3, 2.5e-3),
    ("thumb_CMC_AA", "thumb_CMC_VL", "thumb_MC", (0, -0.005, 0), (-1.5708, 0.7854, 0), -0.3491, 0.3491, 3.3, 0.13587),
    ("thumb_MCP_FE", "thumb_MC", "thumb_MCP_VL", (0.065, -0.006, 0.010392), (0.5236, 0, 0), -0.5236, 1.3963, 1.864, 8e-5),
    ("thumb_MCP_AA", "thumb_MCP_VL", "thumb_PP", (0, 0, 0), (-1.5708, 0, 0), -0.3491, 0.3491, 1.864, 0.03078),
    ("thumb_IP", "thumb_PP", "thumb_DP", (0.039, 0, 0), (1.5708, 0, 0), 0.0, 1.7453, 0.638, 0.00788),
] + [
    row for f, base in (("index", (0.001, 0.0303, 0.0959)), ("middle", (0.0, 0.01, 0.0989)),
                        ("ring", (0.0015, -0.0103, 0.0929)))
    for row in [
        (f"{f}_MCP_FE", "C_MC", f"{f}_MCP_VL", base, (0, -1.5708, -1.5708), -0.17453293, 1.5708, 1.864, 2.21e-3),
        (f"{f}_MCP_AA", f"{f}_MCP_VL", f"{f}_PP", (0, 0, 0), (-1.5708, 0, 0), -0.3491, 0.3491, 1.864, 0.04741),
        (f"{f}_PIP", f"{f}_PP", f"{f}_MP", (0.047, 0, 0), (1.5708, 0, 0), 0.0, 1.7453, 0.638, 0.01824),
        (f"{f}_DIP", f"{f}_MP", f"{f}_DP", (0.0315, 0, 0), (0, 0, 0), 0.0, 1.3963, 0.189369, 0.00455)]
] + [
    ("pinky_CMC", "C_MC", "pinky_MC", (0.01136, -0.0263, 0.0869), (0, 0, 3.1416), 0.0, 0.2618, 0.5285, 0.12541),
    ("pinky_MCP_FE", "pinky_MC", "pinky_MCP_VL", (0.00836, 0.0048, 0), (1.5708, -1.5708, 0), -0.17453293, 1.5708, 1.864, 2.21e-3),
    ("pinky_MCP_AA", "pinky_MCP_VL", "pinky_PP", (0, 0, 0), (-1.5708, 0, 0), -0.3491, 0.3491, 1.864, 0.04741),
    ("pinky_PIP", "pinky_PP", "pinky_MP", (0.047, 0, 0), (1.5708, 0, 0), 0.0, 1.7453, 0.638, 0.01824),
    ("pinky_DIP", "pinky_MP", "pinky_DP", (0.0315, 0, 0), (0, 0, 0), 0.0, 1.3963, 0.189369, 0.00455),
]
SHARPA_TIP = dict(thumb=0.027611, index=0.026009, middle=0.0260092574262507, ring=0.0260092574262503, pinky=0.026009)
SHARPA_PALM_MASS = 0.6506
# Chosen primitive sizes (m): phalanx capsule radii and the palm box (the reference gives STL meshes).
SHARPA_RADIUS = dict(MC=0.012, PP=0.0095, MP=0.0088, DP=0.0082)
SHARPA_PALM = Shape("box", (0.026, 0.084, 0.088), (0.0, 0.001, 0.044))


def sharpa_wave_hand() -> Hand:
    """Sharpa Wave (right), 22 finger DoF. Mount link ``C_MC`` (the palm): +x is the palm normal,
    +z the finger direction, +y the index side, so it follows the hand-frame convention as is.
    Joint names are the reference's without the ``right_`` prefix."""
    joint_rows = {r[0]: r for r in SHARPA_JOINTS}
    children = {r[1] for r in SHARPA_JOINTS}
    links = {"C_MC": Link("C_MC", SHARPA_PALM_MASS, [SHARPA_PALM])}
    joints = []
    for name, parent, child, xyz, rpy, lo, hi, effort, mass in SHARPA_JOINTS:
        shapes = []
        kind = child.split("_")[-1]
        finger = child.split("_")[0]
        if kind in ("PP", "MP"):  # phalanx along +x up to the next joint
            nxt = next(r for r in SHARPA_JOINTS if r[1] == child)
            shapes = [capsule_between((0, 0, 0), nxt[3], SHARPA_RADIUS[kind])]
        elif kind == "DP":
            shapes = [capsule_between((0, 0, 0), (SHARPA_TIP[finger], 0, 0), SHARPA_RADIUS[kind])]
        elif kind == "MC":  # thumb / pinky metacarpal: from its joint to the MCP joint
            nxt = next(r for r in SHARPA_JOINTS if r[1] == child)
            shapes = [capsule_between((0, 0, 0), nxt[3], SHARPA_RADIUS["MC"])]
        links[child] = Link(child, mass, shapes)
        joints.append(Joint(name, parent, child, xyz, rpy, (0, 0, 1), (lo, hi), effort))
    for finger, tip in SHARPA_TIP.items():
        links[f"{finger}_fingertip"] = Link(f"{finger}_fingertip", 1e-6)
        joints.append(Joint(f"{finger}_fingertip_fix_joint", f"{finger}_DP", f"{finger}_fingertip", (tip, 0, 0)))
    assert children <= set(links) and set(joint_rows)
    return Hand("sharpa_wave_right", list(links.values()), joints)


GENERATORS: Dict[str, Callable[[], Hand]] = dict(mano=mano_hand, sharpa_wave=sharpa_wave_hand)


def write_procedural_urdf(name: str, directory: Path) -> Path:
    """Generate hand ``name`` into ``directory`` (content-addressed file name) and return the path."""
    if name not in GENERATORS:
        raise ValueError(f"unknown procedural hand {name!r}; valid: {sorted(GENERATORS)}")
    text = urdf_text(GENERATORS[name]())
    digest = hashlib.sha1(text.encode()).hexdigest()[:12]
    out = Path(directory) / f"{name}_{digest}.urdf"
    if not out.exists():
        atomic_write(out, lambda tmp: tmp.write_text(text))
    return out
