"""YAML configuration: ``configs/*.yaml`` with nested overrides."""
from __future__ import annotations

import copy
import math
from numbers import Number
from pathlib import Path
from typing import Any, Mapping, Optional

import yaml

CONFIG_DIR = Path(__file__).resolve().parent.parent / "configs"
if not CONFIG_DIR.exists():  # installed (non-editable): configs ship as unicross.configs
    CONFIG_DIR = Path(__file__).resolve().parent / "configs"


# sections that hold overrides of another config file: checked where they are applied, merged freely here
FREE_FORM = ("task_config", "reward_config")


def deep_merge(base: dict, override: Optional[Mapping[str, Any]], path: str = "", strict: bool = True,
               defaults: Optional[Mapping[str, Any]] = None) -> dict:
    """Return ``base`` updated by ``override``; unknown keys are an error (typos fail loudly),
    except inside the free-form sections (``FREE_FORM``, or an empty mapping in ``base``).
    ``defaults``: the config file's own values when ``base`` is a saved config (a checkpoint's): a
    mapping empty there (``{mode: w}`` fields such as ``optim.mode_weights``) stays free-form whatever
    the saved config holds in it, so a resumed run may name another mode."""
    out = copy.deepcopy(base)
    for k, v in (override or {}).items():
        if k not in out:
            if strict:
                raise KeyError(f"unknown config key {path + k!r}; valid: {sorted(out)}")
            out[k] = copy.deepcopy(v)
            continue
        d = defaults.get(k) if isinstance(defaults, Mapping) else None
        free = k in FREE_FORM or not out[k] or (isinstance(d, Mapping) and not d)
        if isinstance(out[k], dict) and isinstance(v, Mapping) and free:
            out[k] = deep_merge(out[k], v, path + k + ".", strict=False)
        elif isinstance(out[k], dict) and isinstance(v, Mapping):
            out[k] = deep_merge(out[k], v, path + k + ".", strict=strict, defaults=d)
        else:
            out[k] = _checked(path + k, out[k], copy.deepcopy(v))
    return out


def _kind(v) -> str:
    if isinstance(v, bool):
        return "true/false"
    if isinstance(v, Number):
        return "a number"
    if isinstance(v, str):
        return "a string"
    if isinstance(v, (list, tuple)):
        return "a list"
    if isinstance(v, Mapping):
        return "a section"
    return type(v).__name__


def _checked(key: str, default, value):
    """``value`` if it has its default's kind (a number for a number, ...; ``1e6`` for a whole number
    becomes 1000000), else a clear error. Null defaults and null overrides are free (null means
    "derive it" where a default is null)."""
    if default is None or value is None:
        return value
    if isinstance(default, int) and not isinstance(default, bool) and isinstance(value, float):
        if not value.is_integer():
            raise ValueError(f"config key {key!r} expects a whole number, got {value!r}")
        return int(value)
    want, got = _kind(default), _kind(value)
    if want != got:
        raise ValueError(f"config key {key!r} expects {want} (default {default!r}), got {value!r}")
    return value


# Ranges of the numbers whose wrong values run to garbage rather than fail: "section.key" ->
# (low, low_inclusive); every number must be finite. Pairs ([lo, hi]) are checked elementwise and
# must be ordered.
RANGES = {
    "task": {"sim.sim_freq": (0, False), "sim.control_freq": (0, False), "sim.contact_offset": (0, False),
             "sim.solver_position_iterations": (1, True), "sim.solver_velocity_iterations": (0, True),
             "randomization.mass": (0, False), "randomization.friction": (0, True),
             "randomization.joint_obs_noise": (0, True), "randomization.perturb_scale": (0, True),
             "randomization.perturb_prob": (0, True), "disturbance.max_scale": (0, True),
             "drop_threshold": (0, False), "episode_length.*": (1, True)},
    "ppo": {"collector.total_frames": (1, True), "collector.frames_per_batch": (1, True),
            "collector.horizon": (1, True), "collector.noise_correlation": (0, True), "env.num_envs": (1, True), "env.object_limit": (1, True),
            "env.reconfiguration_freq": (0, True), "gae.gamma": (0, True), "gae.lmbda": (0, True),
            "gae.reward_scale": (0, False), "loss.teacher_coef": (0, True), "loss.teacher_decay": (0, False), "optim.lr": (0, False), "optim.lr_min": (0, False),
            "optim.lr_max": (0, False), "optim.mini_epochs": (1, True), "optim.minibatch_size": (1, True),
            "logging.checkpoint_every": (1, True)},
    "dagger": {"optim.epochs": (1, True), "optim.lr": (0, False), "optim.batch_size": (1, True),
               "optim.grad_steps": (1, True), "buffer.capacity": (1, True), "collector.rollout_steps": (1, True),
               "env.num_envs": (1, True), "env.object_limit": (1, True), "logging.checkpoint_every": (1, True)},
}


def _lookup(cfg: dict, path: str):
    node = cfg
    for k in path.split("."):
        if not isinstance(node, Mapping) or k not in node:
            return []
        node = node[k]
    return [(path, node)]


def validate_ranges(name: str, cfg: dict) -> None:
    """Refuses values of ``configs/<name>.yaml`` that are physically or numerically impossible
    (negative mass, ``sim_freq`` 0, NaN, ...) with a message naming the valid range."""
    for path, (low, inclusive) in RANGES.get(name, {}).items():
        if path.endswith(".*"):
            section = _lookup(cfg, path[:-2])
            found = [(f"{path[:-2]}.{k}", v) for _, sec in section for k, v in sec.items()]
        else:
            found = _lookup(cfg, path)
        for key, value in found:
            values = value if isinstance(value, (list, tuple)) else [value]
            for v in values:
                if v is None:
                    continue
                bad = not isinstance(v, Number) or isinstance(v, bool) or not math.isfinite(v) \
                    or (v < low if inclusive else v <= low)
                if bad:
                    rng = f">= {low}" if inclusive else f"> {low}"
                    raise ValueError(f"config key {key!r} must be {rng} and finite, got {value!r}")
            if isinstance(value, (list, tuple)) and len(value) == 2 and value[0] > value[1]:
                raise ValueError(f"config key {key!r} is a range [low, high], got {value!r}")


def load_config(name: str, overrides: Optional[Mapping[str, Any]] = None) -> dict:
    """Load ``configs/<name>.yaml`` and apply nested ``overrides``."""
    path = CONFIG_DIR / f"{name}.yaml"
    with open(path) as f:
        data = yaml.safe_load(f)
    cfg = deep_merge(data, overrides)
    validate_ranges(name, cfg)
    return cfg


def parse_sim_overrides(pairs) -> dict:
    """``KEY=VALUE`` strings -> overrides of ``configs/task.yaml``'s ``sim`` section (the physics every
    env of a run is built with, e.g. ``solver_position_iterations=8``). Each key must be one of that
    section's and each value a number of its type; ranges are checked as the task checks them."""
    sim = load_config("task")["sim"]
    out = {}
    for pair in pairs or ():
        key, eq, value = str(pair).partition("=")
        if not eq or key not in sim:
            raise ValueError(f"--sim {pair!r}: expected KEY=VALUE with KEY one of {sorted(sim)}")
        kind = type(sim[key])
        try:
            out[key] = kind(value) if kind is float else int(value)
        except ValueError:
            raise ValueError(f"--sim {pair!r}: {key} takes {'a number' if kind is float else 'an integer'}") from None
    load_config("task", {"sim": out})  # out-of-range values fail here, before any simulation
    return out


def preset_names() -> list:
    return sorted(p.stem for p in (CONFIG_DIR / "presets").glob("*.yaml"))


def load_preset(name: str) -> dict:
    """``configs/presets/<name>.yaml``: a named set of overrides (e.g. the paper's exact values)."""
    path = CONFIG_DIR / "presets" / f"{name}.yaml"
    if not path.exists():
        raise ValueError(f"unknown preset {name!r}; valid: {preset_names()}")
    with open(path) as f:
        return yaml.safe_load(f) or {}


class FrozenConfig(dict):
    """A configuration that is fixed once its owner is made (a task's ``cfg``: its compiled step
    math reads it once, ``unicross.compiling.GraphMethod``). Reads as a dict; every write raises.
    Copies (``dict(c)``, ``copy.copy``, ``copy.deepcopy``, pickle) are plain, writable dicts."""

    def _refuse(self, *args, **kwargs):
        raise TypeError("a task's configuration is fixed once the task is made: pass the change when "
                        "making it (gym.make(..., config={...}) or --set env.task_config.KEY=VALUE)")

    __setitem__ = __delitem__ = update = pop = popitem = setdefault = clear = __ior__ = _refuse

    def __copy__(self):
        return {k: v for k, v in self.items()}

    def __deepcopy__(self, memo):
        return {k: copy.deepcopy(v, memo) for k, v in self.items()}

    def __reduce__(self):
        return dict, (self.__deepcopy__({}),)


def freeze(cfg: Mapping) -> FrozenConfig:
    """``cfg`` with every nested dict as a :class:`FrozenConfig`."""
    return FrozenConfig({k: freeze(v) if isinstance(v, Mapping) else v for k, v in cfg.items()})


def atomic_write(path, write) -> Path:
    """Create ``path`` whole or not at all, safely against other processes writing it at once:
    ``write(tmp)`` creates a temporary file of a unique name in the same folder (it keeps ``path``'s
    suffix, so writers that pick a format by extension still do; the writer creates it, so it gets
    the usual permissions), which then replaces ``path``. Several processes that fill the same
    content-addressed cache file (env workers starting on a fresh machine) each rename their own
    file, the last one winning; a failed writer leaves neither file."""
    import os
    import uuid
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.{uuid.uuid4().hex[:8]}.tmp{path.suffix}")
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path
