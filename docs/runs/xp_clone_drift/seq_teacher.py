"""Diagnosis only: DAgger with the rotate x+ rows labelled by the finger sequence the x+ expert clones, computed from
the observation, instead of by the expert network. The sequence answers exactly 0 on every joint once the thumb's
distal command has reached 0.5 rad, whatever else has drifted; the clone answers such states with small non-zero
actions. Does a student distilled on exact labels hold still after the stop?

    python docs/runs/xp_clone_drift/seq_teacher.py check RUN            # the obs-only labels against RUN's buffer
    python docs/runs/xp_clone_drift/seq_teacher.py distill ARGS...      # `unicross distill ARGS...` with the patch

The x+ sequence: index:4:-0.010:0:1000+thumb:4:0.010:0:1000+index:4:0.010:@thumb:0.5+thumb:4:-0.010:@thumb:0.5
(phase 2 cancels phase 1). Within the 400 steps of a rotate episode its clock terms are always on, and its trigger is
the thumb's distal command, which the observation's s^h holds (its command part), so the label is a function of the
observation: phase 1 while that command is under 0.5, 0 from then on. A student made this way is not distilled from
the ten shipped checkpoints (the issue's student): nothing it makes is shipped.
"""
import sys
from pathlib import Path

import torch

from unicross import formulation as F
from unicross.robots.hand import load_hand
from unicross.sequences import Sweep, _action_index, sweep_action

XP = F.MODES.index("rotate_x+")


def sequence_labeller():
    hs = load_hand("allegro")
    phase1 = (sweep_action(hs, Sweep("index", 4, -0.010)) + sweep_action(hs, Sweep("thumb", 4, 0.010))).clamp(-1, 1)
    j = hs.dof + _action_index(hs, "thumb", -1)  # s^h = [joint positions (dof), command (dof)]

    def label(hand: torch.Tensor) -> torch.Tensor:
        stopped = hand[:, j] >= 0.5
        return torch.where(stopped[:, None], torch.zeros_like(phase1), phase1.to(hand))
    return label


def patch_teachers() -> None:
    import unicross.rl.dagger as D
    label = sequence_labeller()
    forward = D.Teachers.forward

    def patched(self, td):
        out = forward(self, td)
        sel = td["goal"][..., :F.NUM_MODES].argmax(-1) == XP
        return torch.where(sel[:, None], label(td["hand"]), out)
    D.Teachers.forward = patched


def check(run: str) -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "benchmarks"))
    from student_fit import load_buffer
    data, _ = load_buffer(Path(run))
    sel = data["mode"] == XP
    hand, clone = data["hand"][sel], data["expert_action"][sel]
    seq = sequence_labeller()(hand)
    stopped = (seq == 0).all(-1)
    err = ((seq - clone) ** 2).mean(-1)
    print(f"x+ rows {int(sel.sum())}: stopped share {float(stopped.float().mean()):.3f}; clone vs sequence MSE "
          f"before the stop {float(err[~stopped].mean()):.2e}, after {float(err[stopped].mean()):.2e}; "
          f"mean |clone| after the stop {float(clone[stopped].abs().mean()):.4f}")


if __name__ == "__main__":
    if sys.argv[1] == "check":
        check(sys.argv[2])
    elif sys.argv[1] == "distill":
        patch_teachers()
        from unicross.cli import main
        sys.exit(main(["distill"] + sys.argv[2:]))
    else:
        sys.exit(__doc__)
