"""Along which hand-frame axis do two opposing fingers pinch the object at an in-hand start? (diagnosis, 2026-11-27)

For the first LIMIT wrappable training objects per group x 3 rotate starts (seeds 0-2, no randomisation) from the
grasp-state dataset GRASPS (default: the shipped one), after one zero-action control step: the unit vector from the
mean hand-frame position of finger A's links touching the object to finger B's, averaged over the starts where both
touch (|component| and signed mean):

    python docs/runs/gait_search/thumb_grasps/pinch_axis.py index ring 10
    python docs/runs/gait_search/thumb_grasps/pinch_axis.py thumb middle 10 configs/grasps/allegro_scripted.pt
"""
import sys

import gymnasium as gym
import torch

import unicross  # noqa: F401
from unicross.geometry import quat_apply, quat_inv
from unicross.objects import get_object_set
from unicross.scripted_grasp import contact_link_fingers


def pinch_direction(u, a: str, b: str):
    """Unit vector [3] in the hand frame from the mean position of finger ``a``'s links touching the object
    (net force > 1 mN) to finger ``b``'s, env 0 of the task ``u``; None unless both touch."""
    fingers = contact_link_fingers(u)
    n = len(fingers)
    pos, quat = u.sensor.poses()  # [1, bodies, 3/4]: the hand frame, the contact links, the object
    rel = quat_apply(quat_inv(quat[0, 0])[None].expand(n, 4), pos[0, 1:1 + n] - pos[0, 0])
    touch = u.link_force[0] > 1e-3
    ia = [i for i, f in enumerate(fingers) if f == a and touch[i]]
    ib = [i for i, f in enumerate(fingers) if f == b and touch[i]]
    if not (ia and ib):
        return None
    d = rel[ib].mean(0) - rel[ia].mean(0)
    return d / d.norm()


if __name__ == "__main__":
    a, b, limit = sys.argv[1], sys.argv[2], int(sys.argv[3])
    grasps = sys.argv[4] if len(sys.argv) > 4 else None
    dirs = []
    for obj in get_object_set("train-wrappable", limit=limit):
        env = gym.make("UniCross-Rotate-v1", obs_mode="state", sim_backend="physx_cpu", render_backend="none",
                       hand="allegro", objects=[obj], randomize=False, axis="z+",
                       **({"grasp_dataset": grasps} if grasps else {}))
        u = env.unwrapped
        for seed in range(3):
            u.reset(seed=seed)
            u.step(torch.zeros(1, u.action_space.shape[-1]))
            d = pinch_direction(u, a, b)
            if d is not None:
                dirs.append(d)
        env.close()
    d = torch.stack(dirs)
    print(f"{a} -> {b}, grasps {grasps or 'shipped'}: {len(d)} starts with both touching; "
          f"mean |x|, |y|, |z| = {[round(v, 2) for v in d.abs().mean(0).tolist()]}, "
          f"mean = {[round(v, 2) for v in d.mean(0).tolist()]}")
