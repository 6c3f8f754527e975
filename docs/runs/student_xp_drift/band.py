"""The dead band both diagnostics here apply: finger actions (after the 6 wrist dimensions) smaller than ``band`` in
magnitude become zero."""
import torch


def zero_small_finger_actions(a: torch.Tensor, band: float) -> torch.Tensor:
    """A copy of the action batch ``a`` [N, dof] with every finger action under ``band`` (action units) zeroed."""
    a = a.clone()
    f = a[:, 6:]
    a[:, 6:] = torch.where(f.abs() < band, torch.zeros_like(f), f)
    return a
