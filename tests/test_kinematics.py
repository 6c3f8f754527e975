"""Forward kinematics (``unicross.kinematics``) gives the link poses PhysX reports, for every hand."""
import pytest
import torch

from conftest import make
from test_hands import SHIPPED_HANDS
from unicross.geometry import quat_angle


@pytest.mark.parametrize("hand", SHIPPED_HANDS)
def test_forward_kinematics_gives_the_poses_physx_reports(hand):
    """Wrist and fingers moved by random actions (the hand closing on the object, so contacts push
    the links too): the tracked bodies' poses computed from the root pose and the joint positions
    equal the poses read from PhysX to float rounding, and the object pose passes through."""
    env = make("UniCross-Grasp-v1", hand=hand, randomize=False, config=dict(grasp=dict(lift_after=20)))
    u = env.unwrapped
    env.reset(seed=0)
    fk = u._make_sensor(forward_kinematics=True)
    assert fk.fk is not None and u.sensor.fk is None  # the suite runs eagerly: reads, not kinematics
    g = torch.Generator().manual_seed(0)
    worst_p, worst_q = 0.0, 0.0
    for _ in range(30):
        env.step((torch.rand(1, u.hand_spec.dof, generator=g) * 2 - 1) * 0.5)
        want_p, want_q = u.sensor.poses()
        raw_p, raw_q = fk.step_poses()
        assert raw_p.shape == (1, 2, 3)
        got_p, got_q = fk.complete(raw_p, raw_q, u.agent.robot.get_qpos())
        assert got_p.shape == want_p.shape and got_q.shape == want_q.shape
        worst_p = max(worst_p, float((got_p - want_p).abs().max()))
        worst_q = max(worst_q, float(quat_angle(got_q, want_q).max()))
    assert worst_p < 1e-5 and worst_q < 1e-4, (worst_p, worst_q)
    # a wrong joint position moves the links: the check can fail
    qpos = u.agent.robot.get_qpos().clone()
    qpos[:, 0] += 0.05  # the first virtual wrist joint carries every link
    bad_p, _ = fk.complete(raw_p, raw_q, qpos)
    assert float((bad_p - want_p).abs().max()) > 1e-3
    env.close()
