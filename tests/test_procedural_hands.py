"""The procedural hands carry the numbers of the kinematic references they are built from."""
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from unicross.robots.hand import build_floating_urdf, load_hand
from unicross.robots.procedural import GENERATORS, urdf_text

REFERENCE = Path(__file__).resolve().parents[2] / "shared" / "reference"


def _table(path, first_col):
    """Rows of the markdown table whose header starts with ``first_col``, as lists of cells."""
    rows, inside = [], False
    for line in path.read_text().splitlines():
        if line.startswith(f"| {first_col} |"):
            inside = True
            continue
        if inside:
            if not line.startswith("|"):
                break
            if not line.startswith("|---"):
                rows.append([c.strip() for c in line.strip("|").split("|")])
    return rows


def _vec(s):
    return np.array([float(v) for v in s.split()])


def _joints(hand):
    root = ET.fromstring(urdf_text(GENERATORS[hand]()).split("\n", 1)[1])
    return root, {j.get("name"): j for j in root.findall("joint")}


@pytest.fixture(scope="module")
def reference():
    if not REFERENCE.exists():
        pytest.skip(f"kinematic references not found at {REFERENCE}")
    return REFERENCE


def test_sharpa_wave_matches_its_reference(reference):
    rows = _table(reference / "sharpa_wave_kinematics.md", "joint")
    root, joints = _joints("sharpa_wave")
    masses = {l.get("name"): float(l.find("inertial/mass").get("value")) for l in root.findall("link")}
    revolute = [r for r in rows if r[1] == "revolute"]
    assert len(revolute) == 22 == sum(j.get("type") == "revolute" for j in joints.values())
    for name, kind, parent, child, xyz, rpy, axis, limits, effort, mass, _ in revolute:
        j = joints[name.removeprefix("right_")]
        assert j.find("parent").get("link") == parent.removeprefix("right_hand_").removeprefix("right_")
        assert np.allclose(_vec(j.find("origin").get("xyz")), _vec(xyz))
        assert np.allclose(_vec(j.find("origin").get("rpy")), _vec(rpy))
        assert np.allclose(_vec(j.find("axis").get("xyz")), _vec(axis))
        lo, hi = (float(v) for v in limits.split(".."))
        assert np.isclose(float(j.find("limit").get("lower")), lo) and np.isclose(float(j.find("limit").get("upper")), hi)
        assert np.isclose(float(j.find("limit").get("effort")), float(effort))
        assert np.isclose(masses[child.removeprefix("right_")], float(mass))


def test_mano_matches_its_reference(reference):
    path = reference / "mano_kinematics.md"
    rows = {r[0]: r for r in _table(path, "joint")}
    root, joints = _joints("mano")
    for f in ("index", "middle", "ring", "pinky", "thumb"):
        first = next(j for n, j in joints.items() if n.startswith(f) and j.find("parent").get("link") == "wrist")
        assert np.allclose(_vec(first.find("origin").get("xyz")), _vec(rows[f"right_{f}1_x"][3]))
        for k in (2, 3):  # PIP/DIP (thumb MCP/IP) offsets
            child = f"{f}{k}"
            j = next(j for j in joints.values() if j.find("child").get("link") == child)
            assert np.allclose(_vec(j.find("origin").get("xyz")), _vec(rows[f"right_{f}{k}_x"][3]))
        tip = joints[f"{f}_tip_joint"]
        assert np.allclose(_vec(tip.find("origin").get("xyz")), _vec(rows[f"right_{f}_tip"][3]))
    caps = {r[0]: r for r in _table(path, "link")}
    links = {l.get("name"): l for l in root.findall("link")}
    for f in ("index", "middle", "ring", "pinky", "thumb"):
        for k in (1, 2, 3):
            ref = caps[f"right_{f}{k}_z"]
            cap = links[f"{f}{k}"].find("collision/geometry/capsule")
            length, radius = (float(re.search(rf"{key}=([0-9.e-]+)", ref[4]).group(1)) for key in ("length", "radius"))
            assert np.isclose(float(cap.get("length")), length) and np.isclose(float(cap.get("radius")), radius)
    masses = dict(line[2:].split(": ") for line in path.read_text().splitlines() if line.startswith("- right_"))
    for name, mass in masses.items():
        assert np.isclose(float(links[name.removeprefix("right_")].find("inertial/mass").get("value")), float(mass))
    # 26 DoF: 6 virtual wrist joints + 4 per finger
    spec = load_hand("mano")
    floating = ET.parse(build_floating_urdf(spec)).getroot()
    assert sum(j.get("type") != "fixed" for j in floating.findall("joint")) == 26 == spec.dof


def test_writers_of_one_cache_file_at_once_both_succeed(tmp_path, monkeypatch):
    """Two env workers on a fresh machine generate the same procedural URDF at once: a second writer
    that runs whole between the first one's write and its rename (here called from inside the
    first one's write) must not take the first one's temporary file away (it did: one shared
    ``.tmp`` name, and the first rename failed with FileNotFoundError)."""
    import unicross.robots.procedural as P
    from unicross.config import atomic_write

    nested = []
    real_write_text = Path.write_text

    def write_text(self, text, *a, **kw):
        n = real_write_text(self, text, *a, **kw)
        if not nested:
            nested.append(None)  # the second writer's own write does not nest again
            nested[0] = P.write_procedural_urdf("mano", tmp_path)
        return n

    monkeypatch.setattr(Path, "write_text", write_text)
    out = P.write_procedural_urdf("mano", tmp_path)
    monkeypatch.undo()
    assert nested == [out] and out.read_text() == urdf_text(GENERATORS["mano"]())
    assert sorted(p.name for p in tmp_path.iterdir()) == [out.name]  # no temporary file left
    plain = tmp_path.parent / f"{tmp_path.name}-plain.urdf"
    plain.write_text("x")
    assert out.stat().st_mode == plain.stat().st_mode  # the permissions of any file written here (not 0600)
    plain.unlink()

    def fail(tmp):
        tmp.write_text("half")
        raise RuntimeError("writer failed")

    with pytest.raises(RuntimeError):
        atomic_write(tmp_path / "x.urdf", fail)
    assert sorted(p.name for p in tmp_path.iterdir()) == [out.name]  # neither the file nor its temporary
