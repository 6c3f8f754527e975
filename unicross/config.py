"""YAML configuration: ``configs/*.yaml`` with nested overrides."""
from __future__ import annotations

import copy
from pathlib import Path
from typing import Any, Mapping, Optional

import yaml

CONFIG_DIR = Path(__file__).resolve().parent.parent / "configs"
if not CONFIG_DIR.exists():  # installed (non-editable): configs ship as unicross.configs
    CONFIG_DIR = Path(__file__).resolve().parent / "configs"


def deep_merge(base: dict, override: Optional[Mapping[str, Any]], path: str = "") -> dict:
    """Return ``base`` updated by ``override``; unknown keys are an error (typos fail loudly),
    except below an empty mapping in ``base``, which is free-form (e.g. ``task_config: {}``)."""
    out = copy.deepcopy(base)
    for k, v in (override or {}).items():
        if k not in out:
            raise KeyError(f"unknown config key {path + k!r}; valid: {sorted(out)}")
        if isinstance(out[k], dict) and out[k] and isinstance(v, Mapping):
            out[k] = deep_merge(out[k], v, path + k + ".")
        else:
            out[k] = copy.deepcopy(v)
    return out


def load_config(name: str, overrides: Optional[Mapping[str, Any]] = None) -> dict:
    """Load ``configs/<name>.yaml`` and apply nested ``overrides``."""
    path = CONFIG_DIR / f"{name}.yaml"
    with open(path) as f:
        data = yaml.safe_load(f)
    return deep_merge(data, overrides)
