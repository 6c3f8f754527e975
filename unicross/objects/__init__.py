"""Object sets of the paper (DESIGN §3) and user meshes, with exact geometry.

Every object is an :class:`ObjectSpec`: a primitive (box, cylinder, sphere, regular prism) with
analytic closest-point geometry, or a user mesh (triangle soup for distances, CoACD convex
parts for collisions). Long axes of cylinders and prisms are the object's local x axis
(SAPIEN's cylinder convention).

Sets (seeded, reproducible; 200 shapes are drawn per (category, type), the first 100 are
``train`` and the last 100 ``test``)::

    train, test                      wrappable + elongated boxes and cylinders (400 each)
    train-wrappable, test-elongated  ... one category only
    unseen                           100 spheres, 100 hexagonal prisms, 200 octagonal prisms
    unseen-wrappable, unseen-elongated
    mesh:/path/to/file.obj           one user mesh (CoACD-decomposed, cached)
"""
from __future__ import annotations

import dataclasses
import hashlib
import math
import os
from pathlib import Path
from typing import List, Optional, Tuple

import numpy as np

from unicross.config import atomic_write
from unicross.geometry import SHAPE_BOX, SHAPE_CYLINDER, SHAPE_MESH, SHAPE_PRISM, SHAPE_SPHERE

CATEGORIES = ("wrappable", "elongated")
WRAPPABLE_RANGE = (0.045, 0.075)
ELONGATED_LENGTH = (0.6, 0.8)
ELONGATED_WIDTH = (0.045, 0.065)
SET_SEED = 20240601


@dataclasses.dataclass(frozen=True)
class ObjectSpec:
    """One rigid object. ``dims``: box (lx, ly, lz) full side lengths; cylinder/prism
    (length, diameter) with diameter = 2 * circumradius; sphere (diameter,);
    mesh: () and ``mesh_path`` set."""

    name: str
    shape: str
    category: str
    dims: Tuple[float, ...]
    n_sides: int = 0
    mesh_path: Optional[str] = None

    def scaled(self, s: float) -> "ObjectSpec":
        if s == 1.0:
            return self
        if self.shape == "mesh":
            raise ValueError("scaling user meshes is not supported; scale the file")
        return dataclasses.replace(self, dims=tuple(d * s for d in self.dims), name=f"{self.name}@{s:g}")

    # ------------------------------------------------------------------ geometry descriptors
    @property
    def shape_type(self) -> int:
        return {"box": SHAPE_BOX, "cylinder": SHAPE_CYLINDER, "sphere": SHAPE_SPHERE,
                "prism": SHAPE_PRISM, "mesh": SHAPE_MESH}[self.shape]

    @property
    def params(self) -> np.ndarray:
        """4 numbers for :func:`unicross.geometry.closest_point_shapes`."""
        d = self.dims
        if self.shape == "box":
            return np.array([d[0] / 2, d[1] / 2, d[2] / 2, 0.0], dtype=np.float32)
        if self.shape == "cylinder":
            return np.array([d[1] / 2, d[0] / 2, 0.0, 0.0], dtype=np.float32)
        if self.shape == "prism":
            return np.array([d[1] / 2, d[0] / 2, float(self.n_sides), 0.0], dtype=np.float32)
        if self.shape == "sphere":
            return np.array([d[0] / 2, 0.0, 0.0, 0.0], dtype=np.float32)
        return np.zeros(4, dtype=np.float32)

    def volume(self) -> float:
        d = self.dims
        if self.shape == "box":
            return d[0] * d[1] * d[2]
        if self.shape == "cylinder":
            return math.pi * (d[1] / 2) ** 2 * d[0]
        if self.shape == "prism":
            r, n = d[1] / 2, self.n_sides
            return 0.5 * n * r * r * math.sin(2 * math.pi / n) * d[0]
        if self.shape == "sphere":
            return 4 / 3 * math.pi * (d[0] / 2) ** 3
        return float(abs(load_user_mesh(self.mesh_path).volume))

    def half_height_on_table(self, upright: bool) -> float:
        """Height of the centre above the table when resting lying (long axis x horizontal)
        or upright (x vertical)."""
        d = self.dims
        if self.shape == "box":
            return d[0] / 2 if upright else d[2] / 2
        if self.shape == "cylinder":
            return d[0] / 2 if upright else d[1] / 2
        if self.shape == "prism":
            r, n = d[1] / 2, self.n_sides
            return d[0] / 2 if upright else r * math.cos(math.pi / n)
        if self.shape == "sphere":
            return d[0] / 2
        m = load_user_mesh(self.mesh_path)
        return float(-m.bounds[0, 0]) if upright else float(-m.bounds[0, 2])

    def trimesh(self, sections: int = 256):
        """A trimesh of the exact surface (cylinder/sphere tessellated finely)."""
        import trimesh
        d = self.dims
        to_x = trimesh.transformations.rotation_matrix(math.pi / 2, [0, 1, 0])  # z axis -> x axis
        if self.shape == "box":
            return trimesh.creation.box(extents=d)
        if self.shape == "cylinder":
            m = trimesh.creation.cylinder(radius=d[1] / 2, height=d[0], sections=sections)
            m.apply_transform(to_x)
            return m
        if self.shape == "prism":
            return trimesh.Trimesh(*prism_mesh(d[1] / 2, d[0] / 2, self.n_sides), process=True)
        if self.shape == "sphere":
            return trimesh.creation.icosphere(subdivisions=5, radius=d[0] / 2)
        return load_user_mesh(self.mesh_path)

    # ------------------------------------------------------------------ simulation
    def add_to_builder(self, builder, density: float, material, can_render: bool, color=None):
        """Add collision (and, only where rendering exists, visual) shapes to a builder."""
        d = self.dims
        kw = dict(material=material, density=density)
        if self.shape == "box":
            builder.add_box_collision(half_size=[d[0] / 2, d[1] / 2, d[2] / 2], **kw)
        elif self.shape == "cylinder":
            builder.add_cylinder_collision(radius=d[1] / 2, half_length=d[0] / 2, **kw)
        elif self.shape == "sphere":
            builder.add_sphere_collision(radius=d[0] / 2, **kw)
        elif self.shape == "prism":
            builder.add_convex_collision_from_file(str(prism_obj_file(d[1] / 2, d[0] / 2, self.n_sides)), **kw)
        else:
            for part in coacd_parts(self.mesh_path):
                builder.add_convex_collision_from_file(str(part), **kw)
        if can_render:
            import sapien
            mat = sapien.render.RenderMaterial(base_color=color or [0.85, 0.45, 0.2, 1.0])
            if self.shape == "box":
                builder.add_box_visual(half_size=[d[0] / 2, d[1] / 2, d[2] / 2], material=mat)
            elif self.shape == "cylinder":
                builder.add_cylinder_visual(radius=d[1] / 2, half_length=d[0] / 2, material=mat)
            elif self.shape == "sphere":
                builder.add_sphere_visual(radius=d[0] / 2, material=mat)
            elif self.shape == "prism":
                builder.add_visual_from_file(str(prism_obj_file(d[1] / 2, d[0] / 2, self.n_sides)), material=mat)
            else:
                builder.add_visual_from_file(str(self.mesh_path), material=mat)


# ----------------------------------------------------------------------------- prisms
def prism_mesh(radius: float, half_len: float, n: int):
    """Vertices/faces of a regular n-gon prism along x; edge normals at angles 2*pi*k/n."""
    ang = (2 * np.arange(n) + 1) * math.pi / n
    ring = np.stack([np.cos(ang), np.sin(ang)], -1) * radius
    v = np.concatenate([np.c_[np.full(n, -half_len), ring], np.c_[np.full(n, half_len), ring]])
    f = []
    for k in range(n):
        k2 = (k + 1) % n
        f += [[k, k2, n + k2], [k, n + k2, n + k]]
    for k in range(1, n - 1):
        f += [[0, k + 1, k], [n, n + k, n + k + 1]]
    return v.astype(np.float64), np.array(f)


def _cache_file(kind: str, key: str, suffix: str) -> Path:
    from unicross.robots.hand import cache_dir
    d = cache_dir() / kind
    d.mkdir(parents=True, exist_ok=True)
    return d / f"{hashlib.sha1(key.encode()).hexdigest()[:16]}{suffix}"


def prism_obj_file(radius: float, half_len: float, n: int) -> Path:
    import trimesh
    out = _cache_file("prisms", f"{radius:.6f}-{half_len:.6f}-{n}", ".obj")
    if not out.exists():
        m = trimesh.Trimesh(*prism_mesh(radius, half_len, n), process=True)
        m.fix_normals()
        atomic_write(out, lambda tmp: m.export(tmp))
    return out


# ----------------------------------------------------------------------------- user meshes
_MESHES: dict = {}


def load_user_mesh(path: str):
    """Load and validate a user mesh file (anything trimesh reads). Raises ValueError on a
    broken mesh (unreadable, empty, non-finite, degenerate)."""
    import trimesh
    path = str(path)
    if path in _MESHES:
        return _MESHES[path]
    if not Path(path).exists():
        raise ValueError(f"mesh file not found: {path}")
    try:
        m = trimesh.load(path, force="mesh", process=True)
    except Exception as e:  # trimesh raises many types
        raise ValueError(f"cannot read mesh {path}: {e}") from e
    if not isinstance(m, trimesh.Trimesh) or len(m.faces) == 0:
        raise ValueError(f"mesh {path} has no triangles")
    if not np.isfinite(m.vertices).all():
        raise ValueError(f"mesh {path} has non-finite vertices")
    ext = m.bounding_box.extents
    if (ext < 1e-4).any():
        raise ValueError(f"mesh {path} is degenerate (extents {ext})")
    if ext.max() > 2.0:
        raise ValueError(f"mesh {path} is {ext.max():.2f} m across; expected metres and a hand-sized object")
    _MESHES[path] = m
    return m


def _coacd_worker(vertices, faces, threshold, queue) -> None:
    import coacd
    coacd.set_log_level("error")
    queue.put([(np.asarray(v), np.asarray(f)) for v, f in coacd.run_coacd(coacd.Mesh(vertices, faces),
                                                                         threshold=threshold)])


COACD_MAX_FACES = 20000  # larger meshes are simplified first (quadric decimation): CoACD's time grows with faces


def simplified_for_coacd(m, path: str = "mesh", max_faces: int = COACD_MAX_FACES):
    """``m`` with at most ``max_faces`` faces (quadric decimation, said on stderr), else ``m`` itself."""
    import sys
    if len(m.faces) <= max_faces:
        return m
    out = m.simplify_quadric_decimation(face_count=max_faces)
    print(f"[unicross] CoACD: {path} simplified from {len(m.faces)} to {len(out.faces)} faces first", file=sys.stderr)
    return out


def _run_coacd(path: str, m, threshold: float, timeout: float) -> list:
    """CoACD in a child process, with progress on stderr and a time bound (a clear error, not a hang)."""
    import multiprocessing as mp
    import sys
    import time
    ctx = mp.get_context("spawn")
    queue = ctx.Queue()
    proc = ctx.Process(target=_coacd_worker, args=(np.asarray(m.vertices), np.asarray(m.faces), threshold, queue),
                       daemon=True)
    m = simplified_for_coacd(m, path)
    t0 = time.time()
    print(f"[unicross] CoACD: decomposing {path} ({len(m.faces)} faces; once per file, cached under "
          f"{_cache_file('coacd', 'x', '').parent}; bound {timeout:.0f} s, UNICROSS_COACD_TIMEOUT)", file=sys.stderr)
    proc.start()
    result, last = None, t0
    while result is None:
        try:
            result = queue.get(timeout=1.0)
        except Exception:  # queue.Empty: still running, or died
            now = time.time()
            if not proc.is_alive():
                raise RuntimeError(f"CoACD failed on {path} (exit code {proc.exitcode})") from None
            if now - t0 > timeout:
                proc.terminate()
                raise ValueError(f"CoACD did not finish {path} ({len(m.faces)} faces) in {timeout:.0f} s: simplify "
                                 f"or close the mesh, or raise UNICROSS_COACD_TIMEOUT") from None
            if now - last >= 30:
                print(f"[unicross] CoACD: {now - t0:.0f} s on {path} ...", file=sys.stderr)
                last = now
    proc.join()
    print(f"[unicross] CoACD: {len(result)} convex parts in {time.time() - t0:.1f} s", file=sys.stderr)
    return result


def coacd_parts(path: str, threshold: float = 0.05, timeout: Optional[float] = None) -> List[Path]:
    """Convex decomposition of a user mesh with CoACD, cached by file content; runs in a child
    process within ``timeout`` seconds (default ``UNICROSS_COACD_TIMEOUT``, 600)."""
    m = load_user_mesh(path)
    key = hashlib.sha1(Path(path).read_bytes()).hexdigest() + f"-{threshold}"
    marker = _cache_file("coacd", key, ".parts")
    if marker.exists():
        parts = [Path(p) for p in marker.read_text().split("\n") if p]
        if all(p.exists() for p in parts):
            return parts
    import trimesh
    if timeout is None:
        timeout = float(os.environ.get("UNICROSS_COACD_TIMEOUT", "600"))
    result = _run_coacd(path, m, threshold, timeout)
    parts = []
    for i, (v, f) in enumerate(result):
        out = marker.with_name(f"{marker.stem}_{i}.obj")
        trimesh.Trimesh(v, f).export(out)
        parts.append(out)
    marker.write_text("\n".join(str(p) for p in parts))
    return parts


# ----------------------------------------------------------------------------- sets
def _u(rng, lo_hi):
    return float(rng.uniform(*lo_hi))


def _generate(category: str, shape: str, n: int, seed_tag: str, n_sides: int = 0) -> List[ObjectSpec]:
    seed = int(hashlib.sha1(f"{SET_SEED}-{category}-{shape}-{n_sides}-{seed_tag}".encode()).hexdigest()[:8], 16)
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        if category == "wrappable":
            if shape == "box":
                dims = (_u(rng, WRAPPABLE_RANGE), _u(rng, WRAPPABLE_RANGE), _u(rng, WRAPPABLE_RANGE))
            elif shape == "sphere":
                dims = (_u(rng, WRAPPABLE_RANGE),)
            else:
                dims = (_u(rng, WRAPPABLE_RANGE), _u(rng, WRAPPABLE_RANGE))
        else:
            length = _u(rng, ELONGATED_LENGTH)
            if shape == "box":
                dims = (length, _u(rng, ELONGATED_WIDTH), _u(rng, ELONGATED_WIDTH))
            else:
                dims = (length, _u(rng, ELONGATED_WIDTH))
        tag = shape if not n_sides else f"prism{n_sides}"
        out.append(ObjectSpec(name=f"{category}-{tag}-{seed_tag}-{i:03d}", shape=shape, category=category,
                              dims=tuple(round(x, 5) for x in dims), n_sides=n_sides))
    return out


def _split(category: str, shape: str, split: str) -> List[ObjectSpec]:
    allo = _generate(category, shape, 200, "boxcyl")
    objs = allo[:100] if split == "train" else allo[100:]
    return [dataclasses.replace(o, name=o.name.replace("-boxcyl-", f"-{split}-")) for o in objs]


def _unseen(category: str) -> List[ObjectSpec]:
    if category == "wrappable":
        return _generate("wrappable", "sphere", 100, "unseen") + _generate("wrappable", "prism", 100, "unseen", 6)
    return _generate("elongated", "prism", 200, "unseen", 8)


SET_NAMES = tuple(f"{s}{c}" for s in ("train", "test", "unseen") for c in ("", "-wrappable", "-elongated"))


def get_object_set(name: str, limit: Optional[int] = None) -> List[ObjectSpec]:
    """Objects of a named set (see module docstring). ``limit`` takes the first ``limit``
    objects of each (category, type) group, in order, so small sets stay balanced."""
    if name.startswith("mesh:"):
        path = name[len("mesh:"):]
        m = load_user_mesh(path)
        ext = m.bounding_box.extents
        category = "elongated" if ext.max() > 0.3 else "wrappable"
        return [ObjectSpec(name=Path(path).stem, shape="mesh", category=category, dims=(), mesh_path=str(Path(path).resolve()))]
    if name not in SET_NAMES:
        raise ValueError(f"unknown object set {name!r}; valid sets: {list(SET_NAMES)} or 'mesh:<path>'")
    split, _, cat = name.partition("-")
    cats = [cat] if cat else list(CATEGORIES)
    groups: List[List[ObjectSpec]] = []
    for c in cats:
        if split == "unseen":
            objs = _unseen(c)
            if c == "wrappable":
                groups += [objs[:100], objs[100:]]
            else:
                groups.append(objs)
        else:
            groups += [_split(c, "box", split), _split(c, "cylinder", split)]
    if limit is not None:
        groups = [g[:limit] for g in groups]
    return [o for g in groups for o in g]


def resolve_objects(objects) -> List[ObjectSpec]:
    """Accept a set name, a single ObjectSpec or a sequence of them."""
    if isinstance(objects, str):
        return get_object_set(objects)
    if isinstance(objects, ObjectSpec):
        return [objects]
    objs = list(objects)
    if not objs or not all(isinstance(o, ObjectSpec) for o in objs):
        raise ValueError("objects must be a set name, an ObjectSpec or a non-empty list of ObjectSpec")
    return objs
