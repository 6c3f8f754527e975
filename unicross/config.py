"""YAML configuration: ``configs/*.yaml`` with nested overrides."""
from __future__ import annotations

import copy
from pathlib import Path
from typing import Any, Mapping, Optional

import yaml

CONFIG_DIR = Path(__file__).resolve().parent.parent / "configs"
if not CONFIG_DIR.exists():  # installed (non-editable): configs ship as unicross.configs
    CONFIG_DIR = Path(__file__).resolve().parent / "configs"


# sections that hold overrides of another config file: checked where they are applied, merged freely here
FREE_FORM = ("task_config", "reward_config")


def deep_merge(base: dict, override: Optional[Mapping[str, Any]], path: str = "", strict: bool = True) -> dict:
    """Return ``base`` updated by ``override``; unknown keys are an error (typos fail loudly),
    except inside the free-form sections (``FREE_FORM``, or an empty mapping in ``base``)."""
    out = copy.deepcopy(base)
    for k, v in (override or {}).items():
        if k not in out:
            if strict:
                raise KeyError(f"unknown config key {path + k!r}; valid: {sorted(out)}")
            out[k] = copy.deepcopy(v)
            continue
        if isinstance(out[k], dict) and isinstance(v, Mapping) and (k in FREE_FORM or not out[k]):
            out[k] = deep_merge(out[k], v, path + k + ".", strict=False)
        elif isinstance(out[k], dict) and isinstance(v, Mapping):
            out[k] = deep_merge(out[k], v, path + k + ".", strict=strict)
        else:
            out[k] = copy.deepcopy(v)
    return out


def load_config(name: str, overrides: Optional[Mapping[str, Any]] = None) -> dict:
    """Load ``configs/<name>.yaml`` and apply nested ``overrides``."""
    path = CONFIG_DIR / f"{name}.yaml"
    with open(path) as f:
        data = yaml.safe_load(f)
    return deep_merge(data, overrides)


def preset_names() -> list:
    return sorted(p.stem for p in (CONFIG_DIR / "presets").glob("*.yaml"))


def load_preset(name: str) -> dict:
    """``configs/presets/<name>.yaml``: a named set of overrides (e.g. the paper's exact values)."""
    path = CONFIG_DIR / "presets" / f"{name}.yaml"
    if not path.exists():
        raise ValueError(f"unknown preset {name!r}; valid: {preset_names()}")
    with open(path) as f:
        return yaml.safe_load(f) or {}
