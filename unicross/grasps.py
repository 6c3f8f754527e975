"""The grasp-state dataset: start states of relocate, rotate and translate episodes.

One file (``torch.save``) holds::

    {"format": "unicross-grasps/1", "hand": <hand name>, "source": "scripted" | "expert:<ckpt>",
     "object_names": [...],                # names of the objects the grasps belong to
     "data": TensorDict(batch_size=[B]) with
        finger_qpos        [B, F]  finger joint positions (hand's finger_joints order)
        finger_target      [B, F]  finger PD targets holding the grasp (the last command)
        wrist_pose         [B, 7]  world pose of the hand frame (p, q wxyz) when recorded
        object_pose_hand   [B, 7]  object pose in the hand frame
        object_id          [B]     index into object_names
        mimic_qpos         [B, M]  (optional) coupled joints' positions, the hand's ``mimic`` order;
                                   without it a restore puts them where the coupling says
        keep_wrist         [B]     (optional, bool) an in-hand start from this row keeps ``wrist_pose``
                                   (rows recorded where a chain left the hand, ``unicross grasps
                                   --chain``); without it, or False: the start height and a random
                                   orientation for rotate / translate, the recorded pose for relocate
    }

The scripted synthesiser (:mod:`unicross.scripted_grasp`) and, later, the grasp expert write this
same format; tasks read it through :class:`GraspSet`.
"""
from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Dict, List, Optional, Sequence

import torch
from tensordict import TensorDict

from unicross.config import CONFIG_DIR, atomic_write

FORMAT = "unicross-grasps/1"
KEYS = ("finger_qpos", "finger_target", "wrist_pose", "object_pose_hand", "object_id")


OPTIONAL_KEYS = ("mimic_qpos", "keep_wrist")
FILL = {"keep_wrist": False}  # optional keys a merge fills where a part lacks them (the others it drops)


def empty_rows() -> Dict[str, list]:
    return {k: [] for k in KEYS + OPTIONAL_KEYS}


def from_rows(hand: str, object_names: Sequence[str], rows: Dict[str, list], tried: Dict[str, int],
              kept: Dict[str, int], source: str):
    """(GraspSet, stats) from per-grasp rows collected by a grasp builder (scripted or expert)."""
    if not rows["object_id"]:
        raise RuntimeError(f"the {source} grasp builder produced no grasp")
    data = TensorDict({k: torch.stack(v) for k, v in rows.items() if v}, batch_size=[len(rows["object_id"])])
    stats = dict(tried=tried, kept=kept, success_rate=sum(kept.values()) / max(1, sum(tried.values())))
    return GraspSet(hand, list(object_names), data, source=source), stats


def grasp_dataset_file(path, what: str = "env.grasp_dataset") -> str:
    """``path`` as a string once it names an existing file (training configs: refused before any
    simulation starts, with how to build one)."""
    if not Path(path).is_file():
        raise FileNotFoundError(f"{what}={path}: no such file (build one with `unicross grasps --expert ... --out FILE`)")
    return str(path)


def default_grasp_path(hand: str) -> Path:
    """The grasp dataset shipped with the project for ``hand`` (``configs/grasps/<hand>.pt``)."""
    return CONFIG_DIR / "grasps" / f"{hand}.pt"


class GraspSet:
    def __init__(self, hand: str, object_names: Sequence[str], data: TensorDict, source: str = "scripted"):
        missing = [k for k in KEYS if k not in data.keys()]
        if missing:
            raise ValueError(f"grasp data lacks keys {missing}")
        self.hand = hand
        self.object_names = list(object_names)
        self.data = data
        self.source = source
        self._index_cache: Dict[tuple, tuple] = {}

    def __len__(self):
        return self.data.batch_size[0]

    def counts(self) -> Dict[str, int]:
        c = Counter(self.data["object_id"].tolist())
        return {self.object_names[i]: c.get(i, 0) for i in range(len(self.object_names))}

    def save(self, path) -> Path:
        state = {"format": FORMAT, "hand": self.hand, "source": self.source,
                 "object_names": self.object_names, "data": self.data.to_dict()}
        return atomic_write(path, lambda tmp: torch.save(state, tmp))

    @classmethod
    def load(cls, path) -> "GraspSet":
        path = Path(path)
        if not path.exists():
            raise FileNotFoundError(f"grasp dataset not found: {path}; build one with "
                                    f"`unicross grasps --objects <set> --out {path}`")
        from unicross.rl.policy_io import read_torch_file
        raw = read_torch_file(path, "grasp dataset")
        if not isinstance(raw, dict) or raw.get("format") != FORMAT:
            raise ValueError(f"{path} is not a {FORMAT} grasp dataset")
        data = TensorDict(raw["data"], batch_size=[len(raw["data"]["object_id"])])
        return cls(raw["hand"], raw["object_names"], data, raw.get("source", "scripted"))

    @staticmethod
    def merge(sets: Sequence["GraspSet"]) -> "GraspSet":
        names: List[str] = []
        parts = []
        for s in sets:
            remap = []
            for n in s.object_names:
                if n not in names:
                    names.append(n)
                remap.append(names.index(n))
            d = s.data.clone()
            d["object_id"] = torch.tensor(remap)[d["object_id"]]
            parts.append(d)
        for k in FILL:  # e.g. grasps from the grasp expert merged with rows recorded after a chain
            if any(k in p.keys() for p in parts):
                for p in parts:
                    if k not in p.keys():
                        p[k] = torch.full(p.batch_size, FILL[k])
        common = set.intersection(*(set(p.keys()) for p in parts))  # other optional keys only where all have them
        parts = [p.select(*sorted(common)) for p in parts]
        sources = list(dict.fromkeys(s.source for s in sets))  # each once, in order
        return GraspSet(sets[0].hand, names, torch.cat(parts), "+".join(sources))

    def sample(self, env_object: torch.Tensor, env_object_names: Sequence[str],
               generator: Optional[torch.Generator] = None, needed: Optional[torch.Tensor] = None) -> TensorDict:
        """One random grasp per env for its object. ``env_object`` indexes ``env_object_names``.
        ``needed`` [B] (default all): the envs that use their grasp; an env that does not (a grasp-mode
        env of a mixed batch) may hold an object without grasps and gets an arbitrary row."""
        key = tuple(env_object_names)
        if key not in self._index_cache:
            # table [num_env_objects, max_grasps] of dataset rows, padded by repetition
            ids = self.data["object_id"]
            rows, counts = [], []
            for name in env_object_names:
                r = torch.nonzero(ids == self.object_names.index(name)).flatten() if name in self.object_names \
                    else torch.zeros(0, dtype=torch.long)
                rows.append(r)
                counts.append(len(r))
            width = max(1, max(counts))
            table = torch.stack([torch.cat([r, r[:1].repeat(width - len(r))]) if len(r) else torch.zeros(width, dtype=torch.long)
                                 for r in rows])
            self._index_cache[key] = (table, torch.tensor(counts))
        table, counts = self._index_cache[key]
        dev = env_object.device
        obj = env_object.cpu()
        need = torch.ones(len(obj), dtype=torch.bool) if needed is None else needed.cpu()
        if (need & (counts[obj] == 0)).any():
            bad = sorted({env_object_names[i] for i in obj[need & (counts[obj] == 0)].tolist()})
            raise ValueError(f"no grasps for objects {bad}")
        u = torch.rand(len(obj), generator=generator, device=dev).cpu()
        c = counts[obj].clamp(min=1)  # an object without grasps (not needed): row 0 of its padded table
        pick = (u * c).long().clamp(max=c - 1)
        rows = table[obj, pick]
        return self.data[rows].to(dev)
