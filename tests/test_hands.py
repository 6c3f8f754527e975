"""Hands are data: a new hand needs one description and a registration, no task/training code."""
import yaml
import torch

from conftest import make
from unicross.cli import main as cli
from unicross.robots.hand import CONFIG_DIR, available_hands, load_hand, register_hand


def test_throwaway_hand_runs_a_step(tmp_path):
    desc = yaml.safe_load(open(CONFIG_DIR / "hands" / "allegro.yaml"))
    desc.update(name="allegro_three_links", palm_point=[0.05, 0.0, 0.03],
                contact_links=["base_link", "link_3.0_tip", "link_15.0_tip"])
    path = tmp_path / "hand.yaml"
    path.write_text(yaml.safe_dump(desc))
    register_hand(path)
    assert "allegro_three_links" in available_hands()
    env = make("UniCross-Grasp-v1", hand="allegro_three_links")
    obs, _ = env.reset(seed=0)
    assert obs.shape == (1, 2 * 22 + 5 * 3 + 55)
    obs, *_ = env.step(torch.zeros(22))
    assert torch.isfinite(obs).all()
    env.close()


def test_unknown_hand_lists_the_valid_ones(capsys):
    import pytest
    with pytest.raises(ValueError, match="allegro"):
        load_hand("robo")
    assert cli(["hands"]) == 0
    assert "allegro" in capsys.readouterr().out


def test_virtual_wrist_moves_the_hand_as_documented():
    """+wrist_tz moves the hand-frame origin along +z of the root frame; joints stay in limits."""
    env = make("UniCross-Grasp-v1", randomize=False, config=dict(grasp=dict(lift_after=None)))
    u = env.unwrapped
    env.reset(seed=0)
    a = torch.zeros(1, 22)
    a[0, 2] = 1.0
    for _ in range(5):
        env.step(a)
    x = u.cur_rel.x_hr[0]
    assert x[2] > 0.05 and abs(x[0]) < 0.01 and abs(x[1]) < 0.01
    q = u.agent.robot.get_qpos()[0, u._qidx]
    assert torch.all(q >= u.q_lower - 1e-3) and torch.all(q <= u.q_upper + 1e-3)
    env.close()
