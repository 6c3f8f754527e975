"""Hands are data: every registered hand runs every task id; a new hand needs one description and
a registration, no task/training code; hand frames follow one convention."""
import numpy as np
import pytest
import torch
import yaml

from conftest import make
from unicross import formulation as F
from unicross.cli import main as cli
from unicross.grasps import GraspSet, default_grasp_path
from unicross.objects import get_object_set
from unicross.robots.hand import CONFIG_DIR, available_hands, load_hand, register_hand

SHIPPED_HANDS = sorted(p.stem for p in (CONFIG_DIR / "hands").glob("*.yaml"))
TASKS = ["UniCross-Grasp-v1", "UniCross-Relocate-v1", "UniCross-Rotate-v1", "UniCross-Translate-v1",
         "UniCross-MultiSkill-v1", "UniCross-Chain-v1"]


def test_the_paper_hands_and_the_shipped_mani_skill_hands_are_registered(capsys):
    assert {"allegro", "mano", "sharpa_wave", "inspire", "ability"} <= set(SHIPPED_HANDS)
    dofs = {h: load_hand(h).dof for h in SHIPPED_HANDS}
    assert dofs["allegro"] == 22 and dofs["mano"] == 26 and dofs["sharpa_wave"] == 28
    assert cli(["hands"]) == 0
    out = capsys.readouterr().out
    for h in SHIPPED_HANDS:
        line = next(l for l in out.splitlines() if l.startswith(h + " "))
        assert str(dofs[h]) in line.split()


def _first_with_grasps(hand):
    """Per category, the first training object that the hand's shipped dataset can start from
    (None where the dataset has no grasp of that category)."""
    gs = GraspSet.load(default_grasp_path(hand))
    have = {n for n, c in gs.counts().items() if c > 0}
    objs = get_object_set("train")
    return {cat: next((o for o in objs if o.category == cat and o.name in have), None)
            for cat in ("wrappable", "elongated")}


@pytest.mark.parametrize("hand", SHIPPED_HANDS)
def test_every_task_id_steps_within_joint_limits(hand):
    spec = load_hand(hand)
    picks = _first_with_grasps(hand)
    assert picks["wrappable"] is not None, f"{hand}: no wrappable grasp in the shipped dataset"
    objs = [o for o in picks.values() if o is not None]
    L = len(spec.contact_links)
    g = torch.Generator().manual_seed(0)
    for task in TASKS:
        if task == "UniCross-Translate-v1" and picks["elongated"] is None:
            # a hand without elongated grasps (Ability: no finger abduction) cannot start translate
            # episodes; it must say so before any simulation
            elongated = get_object_set("train-elongated", limit=1)
            with pytest.raises(ValueError, match="has no grasps"):
                make(task, hand=hand, objects=elongated, randomize=False)
            continue
        env = make(task, hand=hand, objects=objs, randomize=False)
        u = env.unwrapped
        obs, _ = env.reset(seed=0)
        assert obs.shape == (1, 2 * spec.dof + 5 * L + F.GOAL_DIM), task
        assert env.action_space.shape[-1] == spec.dof
        robot = u.agent.robot
        lim = robot.get_qlimits()[0]
        for _ in range(4):
            obs, reward, *_ = env.step(torch.rand(1, spec.dof, generator=g) * 2 - 1)
            assert torch.isfinite(obs).all() and torch.isfinite(reward).all(), task
            # drive targets (actuated and coupled joints) never leave the limits ...
            targets = torch.cat([u.command, u._follow(u.command)], dim=-1)[0]
            tl = lim[u._drive_idx]
            assert torch.all(targets >= tl[:, 0] - 1e-6) and torch.all(targets <= tl[:, 1] + 1e-6), task
            # ... and joints stay within them up to what PhysX gives way under hard contacts (the
            # random wrist actions press the held object into the fingers with the stiff wrist PD)
            q = robot.get_qpos()[0]
            assert torch.all(q >= lim[:, 0] - 0.06) and torch.all(q <= lim[:, 1] + 0.06), (task, q, lim)
        env.close()


@pytest.mark.parametrize("hand", SHIPPED_HANDS)
def test_virtual_wrist_moves_the_hand_in_the_root_frame(hand):
    """+wrist_tz moves the hand-frame origin along +z of the root frame; +wrist_rz then turns the
    hand about the root z axis through the palm point (the origin stays put)."""
    spec = load_hand(hand)
    env = make("UniCross-Grasp-v1", hand=hand, randomize=False, config=dict(grasp=dict(lift_after=None)))
    u = env.unwrapped
    env.reset(seed=0)
    a = torch.zeros(1, spec.dof)
    a[0, 2] = 1.0
    for _ in range(5):
        env.step(a)
    x = u.cur_rel.x_hr[0].clone()
    assert x[2] > 0.05 and abs(x[0]) < 0.01 and abs(x[1]) < 0.01
    a = torch.zeros(1, spec.dof)
    a[0, 2] = 0.0
    a[0, 5] = 1.0
    env.step(a)  # targets follow the reference: keep the height, turn about z
    for _ in range(4):
        env.step(a)
    q = u.cur_rel.q_hr[0]
    angle = 2 * torch.atan2(q[1:].norm(), q[0].abs())
    axis = q[1:] / q[1:].norm() * torch.sign(q[0])
    assert angle > 0.2 and axis[2] > 0.99, (angle, axis)
    assert (u.cur_rel.x_hr[0] - x).norm() < 0.01
    env.close()


def _finger_links(model, spec):
    """Links below each finger's first joint, by finger name."""
    joint_child = {name: child for kids in model.children.values() for name, _, child, _, _ in kids}
    out = {}
    for finger, joints in spec.fingers.items():
        stack, links = [joint_child[joints[0]]], []
        while stack:
            link = stack.pop()
            links.append(link)
            stack += [c for _, _, c, _, _ in model.children.get(link, [])]
        out[finger] = links
    return out


@pytest.mark.parametrize("hand", SHIPPED_HANDS)
def test_hand_frame_convention(hand):
    """Every hand frame: fingers extend along +z, flexing (closing) moves them towards +x (the palm
    normal), and the index finger lies on the +y side of the other long fingers."""
    from unicross.render import HandModel
    spec = load_hand(hand)
    model = HandModel(hand)
    fingers = _finger_links(model, spec)
    wrist = np.array([0, 0, 0, 1, 0, 0, 0.0])
    q = np.zeros(spec.dof)
    open_pose = model.link_poses(wrist, q)
    q[6:] = spec.closing_deltas()
    closed = model.link_poses(wrist, q)
    long_fingers = [f for f in fingers if f != "thumb"]
    for f in long_fingers:
        tip = fingers[f][-1]
        assert open_pose[tip][2, 3] > 0.0, (f, open_pose[tip][:3, 3])
        assert closed[tip][0, 3] > open_pose[tip][0, 3] + 0.005, (f, open_pose[tip][:3, 3], closed[tip][:3, 3])
    y = {f: np.mean([open_pose[l][1, 3] for l in fingers[f]]) for f in long_fingers}
    assert y["index"] > max(v for f, v in y.items() if f != "index")


@pytest.mark.parametrize("hand", [h for h in SHIPPED_HANDS if load_hand(h).mimic])
def test_mimic_followers_track_their_leaders(hand):
    spec = load_hand(hand)
    env = make("UniCross-Grasp-v1", hand=hand, randomize=False, config=dict(grasp=dict(lift_after=None)))
    u = env.unwrapped
    env.reset(seed=0)
    a = torch.zeros(1, spec.dof)
    a[0, 6:] = torch.sign(torch.from_numpy(spec.closing_deltas()))
    for _ in range(12):
        env.step(a)
    robot = u.agent.robot
    names = [j.name for j in robot.active_joints]
    q = robot.get_qpos()[0]
    for follower, leader, k, o in spec.resolved_mimic():
        lo, hi = robot.get_qlimits()[0, names.index(follower)]
        expected = float(np.clip(k * q[names.index(leader)] + o, lo, hi))
        assert abs(float(q[names.index(follower)]) - expected) < 0.15, (follower, expected)
        target = u._cpu_joints[u._drive_idx.tolist().index(names.index(follower))].get_drive_target()
        cmd = float(u.command[0, 6 + spec.finger_joints.index(leader)])
        assert abs(float(np.asarray(target).ravel()[0]) - float(np.clip(k * cmd + o, lo, hi))) < 1e-5
    env.close()


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


def test_bad_hand_descriptions_fail_before_simulation(tmp_path):
    with pytest.raises(ValueError, match="allegro"):
        load_hand("robo")
    desc = yaml.safe_load(open(CONFIG_DIR / "hands" / "mano.yaml"))
    bad = dict(desc, name="bad1", finger_direction=[0.0, -1.0, 0.0])  # parallel to the palm normal
    with pytest.raises(ValueError, match="perpendicular"):
        register_hand(bad)
    bad = dict(desc, name="bad2", init_poses=dict(wrappable=[0.0] * 3, elongated=[0.0] * 20))
    with pytest.raises(ValueError, match="3 values"):
        register_hand(bad)
    bad = dict(desc, name="bad3", mimic={"index_tip_joint": {"joint": "nonexistent"}})
    with pytest.raises(ValueError, match="not a finger joint"):
        register_hand(bad)
