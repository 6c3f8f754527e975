"""The formulation and the reward terms on synthetic tensors: no simulator, seconds.

Target rules (paper Table 1 as data), the action mapping, the goal features and every registered
reward term are pure functions of batched tensors; these tests pin what they compute.
"""
import math

import pytest
import torch

from unicross import formulation as F
from unicross import rewards as RW
from unicross.config import load_config
from unicross.geometry import quat_angle, quat_from_axis_angle, quat_positive

pytestmark = pytest.mark.unit

P = F.MotionParams(dt=0.05, v_max=0.1, omega_max=1.0, relocate_v=0.3, relocate_omega=1.5)


def random_relational(n: int, g: torch.Generator) -> F.Relational:
    slots = {}
    for s in F.SLOTS:
        if s.startswith("x"):
            slots[s] = 0.2 * torch.randn(n, 3, generator=g)
        else:
            q = torch.randn(n, 4, generator=g)
            slots[s] = quat_positive(q / q.norm(dim=-1, keepdim=True))
    return F.Relational(**slots)


def batch(mode_names, seed=0):
    g = torch.Generator().manual_seed(seed)
    n = len(mode_names)
    mode = torch.tensor([F.MODES.index(m) for m in mode_names])
    cur, init = random_relational(n, g), random_relational(n, g)
    final = random_relational(n, g)
    axis = F.MODE_AXES[mode].float()
    return mode, cur, init, final.x_or, final.q_or, axis


def test_fixed_and_free_slots_follow_the_target_table():
    mode, cur, init, fx, fq, axis = batch(list(F.MODES))
    tgt = F.update_targets(mode, cur, init, fx, fq, axis, P)
    for i, m in enumerate(F.MODES):
        rules = F.SKILL_TARGETS[F.mode_skill(m)]
        for s in F.SLOTS:
            if rules[s] == "fixed":
                assert torch.equal(getattr(tgt, s)[i], getattr(init, s)[i]), (m, s)
            elif rules[s] == "free":
                assert torch.equal(getattr(tgt, s)[i], getattr(cur, s)[i]), (m, s)


def test_tracked_rules_move_at_their_speed():
    mode, cur, init, fx, fq, axis = batch(["translate_z+", "rotate_x-", "relocate"])
    tgt = F.update_targets(mode, cur, init, fx, fq, axis, P)
    # translate: the hand-frame object target is one step of v_max along d^h
    assert torch.allclose(tgt.x_oh[0] - cur.x_oh[0], P.v_max * P.dt * axis[0], atol=1e-7)
    # rotate: one step of omega_max about d^h
    assert quat_angle(tgt.q_oh[1:2], cur.q_oh[1:2]).item() == pytest.approx(P.omega_max * P.dt, abs=1e-5)
    step = quat_positive(quat_from_axis_angle(axis[1:2], torch.tensor([P.omega_max * P.dt])))
    assert torch.allclose(quat_angle(tgt.q_oh[1:2], cur.q_oh[1:2]), quat_angle(step, torch.tensor([[1.0, 0, 0, 0]])),
                          atol=1e-5)
    # relocate: the root-frame object target moves relocate_v * dt towards the final pose
    d0 = torch.linalg.norm(fx[2] - cur.x_or[2])
    d1 = torch.linalg.norm(fx[2] - tgt.x_or[2])
    assert (d0 - d1).item() == pytest.approx(min(P.relocate_v * P.dt, d0.item()), abs=1e-6)


def test_one_skill_path_equals_the_mixed_batch_path():
    """Envs sharing one skill may take the single-rule path; it must equal the per-env selection."""
    for m in ("grasp", "relocate", "rotate_y+", "translate_z-"):
        mode, cur, init, fx, fq, axis = batch([m] * 4, seed=3)
        mixed = F.update_targets(mode, cur, init, fx, fq, axis, P)
        single = F.update_targets(mode, cur, init, fx, fq, axis, P, skill=F.mode_skill(m))
        assert torch.allclose(mixed.flat(), single.flat(), atol=1e-7), m


def test_action_mapping_wrist_from_target_and_fingers_from_command():
    n, dof = 3, 22
    g = torch.Generator().manual_seed(1)
    a = torch.rand(n, dof, generator=g) * 2 - 1
    prev = torch.randn(n, dof, generator=g)
    ref = torch.randn(n, 6, generator=g)
    scale = torch.full((dof,), 0.1)
    lo, hi = torch.full((dof,), -10.0), torch.full((dof,), 10.0)
    out = F.map_action(a, prev, ref, scale, lo, hi)
    assert torch.allclose(out[:, :6], ref + 0.1 * a[:, :6])
    assert torch.allclose(out[:, 6:], prev[:, 6:] + 0.1 * a[:, 6:])
    ablated = F.map_action(a, prev, ref, scale, lo, hi, wrist_from_target=False)  # W/o target action
    assert torch.allclose(ablated, prev + 0.1 * a)
    clamped = F.map_action(torch.ones(n, dof), prev, ref, torch.full((dof,), 100.0), lo, hi)
    assert torch.equal(clamped, hi.expand(n, dof))


def test_goal_features_layout():
    mode, cur, init, fx, fq, axis = batch(["rotate_z+", "grasp"])
    g = F.goal_features(mode, axis, cur, init)
    assert g.shape == (2, F.GOAL_DIM)
    assert g[0, :F.NUM_MODES].argmax().item() == F.MODES.index("rotate_z+")
    assert torch.equal(g[:, F.NUM_MODES:F.NUM_MODES + 3], axis)
    assert torch.equal(g[:, -21:], init.flat())
    assert torch.count_nonzero(F.goal_features(mode, axis, cur, init, zero_target=True)[:, -21:]) == 0


def measurements(n: int, L: int = 5, seed: int = 0) -> dict:
    g = torch.Generator().manual_seed(seed)
    rel = random_relational(n, g)
    return dict(link_distance=torch.rand(n, L, generator=g), contact=torch.rand(n, L, generator=g) > 0.5,
                force_clipped=torch.rand(n, L, generator=g), speed_along_axis=torch.randn(n, generator=g),
                speed_cap=torch.full((n,), 0.1), success=torch.rand(n, generator=g) > 0.5,
                goal_err=torch.rand(n, 2, generator=g), goal_err_prev=torch.rand(n, 2, generator=g),
                relational=rel, reward_targets=rel.clone(), finger_qpos=torch.randn(n, 16, generator=g),
                finger_qpos0=torch.randn(n, 16, generator=g), hand_lin_vel=torch.randn(n, 3, generator=g),
                hand_ang_vel=torch.randn(n, 3, generator=g), finger_torque=torch.randn(n, 16, generator=g),
                drop=torch.rand(n, generator=g) > 0.8, held=torch.ones(n, dtype=torch.bool),
                success_paid=torch.rand(n, generator=g) * 50, obj_speed_hand=torch.rand(n, generator=g),
                obj_angspeed_hand=torch.rand(n, generator=g))


def test_every_registered_term_is_computed_finite_and_per_env():
    terms = RW.RewardTerms(load_config("reward"), "cpu")
    mode = torch.arange(F.NUM_MODES)
    out = terms(mode, measurements(F.NUM_MODES))
    assert tuple(out) == RW.term_names()
    for k, v in out.items():
        assert v.shape == (F.NUM_MODES,) and torch.isfinite(v).all(), k


def test_tracking_is_zero_on_target_and_saturates_when_lost():
    terms = RW.RewardTerms(load_config("reward"), "cpu")
    c = terms.coefficients("track")
    m = measurements(4)
    assert torch.allclose(RW.tracking_reward(m, c, torch.zeros(4, dtype=torch.long)), torch.zeros(4), atol=1e-5)
    far = m["relational"].clone()
    far.x_or = far.x_or + 100.0  # an object lost far away: the position part saturates
    m2 = dict(m, relational=far)
    r = RW.tracking_reward(m2, c, torch.zeros(4, dtype=torch.long))
    assert torch.allclose(r, c["pos"][1] * torch.tensor(c["max_pos"]) ** 2, atol=1e-5)


def test_contact_distance_saturates_and_motion_is_capped():
    cfg = load_config("reward")
    c = RW.RewardTerms(cfg, "cpu").coefficients("contact")
    m = measurements(2)
    mode = torch.tensor([F.MODES.index("grasp")] * 2)
    near = RW.contact_reward(dict(m, link_distance=torch.full((2, 5), c["max_distance"])), c, mode)
    far = RW.contact_reward(dict(m, link_distance=torch.full((2, 5), 50.0)), c, mode)
    assert torch.equal(near, far)
    cm = RW.RewardTerms(cfg, "cpu").coefficients("motion")
    mode = torch.tensor([F.MODES.index("translate_z+")] * 2)
    fast = RW.motion_reward(dict(m, speed_along_axis=torch.tensor([5.0, -5.0])), cm, mode)
    w = cm["w_p"][mode[0]]
    assert fast[0].item() == pytest.approx(float(w * 0.1))  # capped at v_max
    assert fast[1].item() == pytest.approx(float(w * -0.1 * cfg["motion_floor"]))  # floored (ours)
    paper = RW.RewardTerms(dict(cfg, motion_floor=math.inf), "cpu").coefficients("motion")
    fast = RW.motion_reward(dict(m, speed_along_axis=torch.tensor([5.0, -5.0])), paper, mode)
    assert fast[1].item() == pytest.approx(float(w * -5.0))  # the paper's: unbounded below while held
    grasp = torch.tensor([F.MODES.index("grasp")] * 2)  # a zero cap and weight stay finite without a floor
    assert torch.isfinite(RW.motion_reward(dict(m, speed_cap=torch.zeros(2)), paper, grasp)).all()
    lost = RW.motion_reward(dict(m, speed_along_axis=torch.tensor([5.0, -5.0]), held=torch.zeros(2, dtype=torch.bool)),
                            cm, mode)
    assert torch.equal(lost, torch.zeros(2))  # nothing after a drop: the paper's episode would have ended


def test_success_bonus_is_taken_back_at_a_drop_where_configured():
    """``success_revoke_on_drop``: at the step a drop is detected (dropped now, held before) the
    success term returns minus what it paid in the episode; later dropped steps, a held object and
    skills without the switch are untouched."""
    cfg = load_config("reward")
    assert cfg["success_revoke_on_drop"]["rotate"] and not cfg["success_revoke_on_drop"]["translate"]
    c = RW.RewardTerms(cfg, "cpu").coefficients("success")
    m = dict(success=torch.tensor([False, False, True, False]), drop=torch.tensor([True, True, False, True]),
             held=torch.tensor([True, False, True, True]), success_paid=torch.tensor([120.0, 120.0, 30.0, 120.0]),
             goal_err=torch.full((4, 2), 0.5))
    rot = torch.tensor([F.MODES.index("rotate_y-")] * 3 + [F.MODES.index("translate_z+")])
    w = cfg["success"]["rotate"]
    assert RW.success_reward(m, c, rot).tolist() == [-120.0, 0.0, w, 0.0]


def test_success_bonus_can_require_the_object_near_its_goal_position():
    """``success_max_pos_error``: the bonus is paid only while the object is within d of its final
    root-frame position (inf, the default, pays it wherever the object is); the take-back at a drop
    is unchanged."""
    assert set(load_config("reward")["success_max_pos_error"].values()) == {float("inf")}
    cfg = load_config("reward", {"success_max_pos_error": {"rotate": 0.04}})
    c = RW.RewardTerms(cfg, "cpu").coefficients("success")
    goal_err = torch.tensor([[0.05, 0.0], [0.03, 0.0], [0.10, 0.0], [0.50, 0.0]])  # [position, angle]
    m = dict(success=torch.ones(4, dtype=torch.bool), drop=torch.tensor([False, False, True, False]),
             held=torch.ones(4, dtype=torch.bool), success_paid=torch.tensor([0.0, 0.0, 50.0, 0.0]),
             goal_err=goal_err)
    mode = torch.tensor([F.MODES.index("rotate_y-")] * 3 + [F.MODES.index("translate_z+")])
    w = cfg["success"]["rotate"]
    # an object rolled 5 cm away earns nothing; translate (no gate) is paid 50 cm from its goal;
    # the drop takes back what was paid
    assert RW.success_reward(m, c, mode).tolist() == [0.0, w, -50.0, cfg["success"]["translate"]]


def test_progress_term_telescopes_to_the_error_reduction():
    """Potential-based: over any path the sum is w_pos (e_0 - e_T) + w_rot (theta_0 - theta_T)."""
    c = RW.RewardTerms(load_config("reward"), "cpu").coefficients("progress")
    mode = torch.tensor([F.MODES.index("relocate")])
    g = torch.Generator().manual_seed(2)
    errs = torch.rand(20, 1, 2, generator=g) * torch.tensor([0.05, math.pi])  # under the position cap
    total = sum(RW.progress_reward(dict(goal_err_prev=errs[t - 1], goal_err=errs[t]), c, mode) for t in range(1, 20))
    expect = c["w_pos"][mode] * (errs[0, :, 0] - errs[-1, :, 0]) + c["w_rot"][mode] * (errs[0, :, 1] - errs[-1, :, 1])
    assert torch.allclose(total, expect, atol=1e-6)


def test_settle_term_charges_the_speed_in_the_hand_only_while_the_success_holds():
    """In units of the dataset's settle test, the larger of the two ratios, capped; 0 by default (the paper's)."""
    cfg = load_config("reward", {"settle": {"weight": {"grasp": 2.0}}})
    c = RW.RewardTerms(cfg, "cpu").coefficients("settle")
    assert float(RW.RewardTerms(load_config("reward"), "cpu").coefficients("settle")["w"].abs().sum()) == 0.0
    m = dict(obj_speed_hand=torch.tensor([0.1, 0.01, 1.0, 0.1, 0.1]),
             obj_angspeed_hand=torch.tensor([0.1, 1.5, 0.0, 0.1, 0.1]),
             success=torch.tensor([True, True, True, False, True]))
    mode = torch.tensor([F.MODES.index("grasp")] * 4 + [F.MODES.index("relocate")])
    assert torch.allclose(RW.settle_reward(m, c, mode), torch.tensor([-4.0, -6.0, -10.0, 0.0, 0.0]))


def test_frozen_config_refuses_writes_and_copies_are_plain():
    import copy
    import pickle
    from unicross.config import FrozenConfig, freeze
    cfg = freeze({"a": {"b": 1}, "c": [1, 2]})
    assert isinstance(cfg["a"], FrozenConfig) and cfg["a"]["b"] == 1 and dict(cfg)["c"] == [1, 2]
    for write in (lambda: cfg.__setitem__("a", 2), lambda: cfg["a"].__setitem__("b", 2), lambda: cfg.update(a=1),
                  lambda: cfg.pop("a"), lambda: cfg.setdefault("z", 1), lambda: cfg.clear(), lambda: cfg["a"].popitem()):
        with pytest.raises(TypeError, match="fixed once the task is made"):
            write()
    for c in (copy.deepcopy(cfg), pickle.loads(pickle.dumps(cfg))):
        assert type(c) is dict and type(c["a"]) is dict and c == {"a": {"b": 1}, "c": [1, 2]}
        c["a"]["b"] = 5
    assert cfg["a"]["b"] == 1 and type(copy.copy(cfg)) is dict


def test_an_evaluations_markdown_sits_beside_its_json_under_its_own_name():
    from pathlib import Path
    from unicross.cli import markdown_path
    assert markdown_path(Path("d/e.json")) == Path("d/e.md")
    assert markdown_path(Path("d/heldout")) == Path("d/heldout.md")
    assert markdown_path(Path("d/lookahead1.5")) == Path("d/lookahead1.5.md")  # was d/lookahead1.md


def test_the_wrist_can_start_with_its_own_exploration_noise():
    from unicross.rl.models import make_models
    dims = dict(hand=44, object=105, goal=37)
    head = make_models(dims, 22, None, dict(init_log_std=-4.0, init_log_std_wrist=-1.0))[0].module[0].module
    assert head.log_std[:6].tolist() == [-1.0] * 6 and head.log_std[6:].tolist() == [-4.0] * 16
    head = make_models(dims, 22, None, dict(init_log_std=-2.0))[0].module[0].module
    assert head.log_std.tolist() == [-2.0] * 22


def test_training_reads_another_grasp_dataset_only_for_in_hand_skills(tmp_path):
    """env.grasp_dataset reaches the in-hand tasks' constructor; a missing file is refused before any
    simulation; the grasp skill (starts on the table) ignores it."""
    from unicross.rl.ppo import env_kwargs_for
    env = dict(load_config("ppo")["env"])
    assert "grasp_dataset" not in env_kwargs_for("translate", "z+", "allegro", env)
    env["grasp_dataset"] = str(tmp_path / "none.pt")
    with pytest.raises(FileNotFoundError, match="env.grasp_dataset"):
        env_kwargs_for("translate", "z+", "allegro", env)
    assert "grasp_dataset" not in env_kwargs_for("grasp", None, "allegro", env)
    (tmp_path / "none.pt").write_bytes(b"")
    assert env_kwargs_for("relocate", None, "allegro", env)["grasp_dataset"] == str(tmp_path / "none.pt")


def test_training_ends_grasp_episodes_at_a_drop_and_in_hand_episodes_not():
    """configs/ppo.yaml's env.terminate_on_drop is per skill (grasp: the paper's termination; the others
    go on, penalised); a run's own task_config.terminate_on_drop wins, for every skill; a skill name
    that does not exist is refused."""
    from unicross.rl.ppo import env_kwargs_for
    env = load_config("ppo")["env"]
    ends = {sk: env_kwargs_for(sk, ax, "allegro", env)["config"]["terminate_on_drop"]
            for sk, ax in (("grasp", None), ("relocate", None), ("rotate", "x+"), ("translate", "z-"))}
    assert ends == dict(grasp=True, relocate=False, rotate=False, translate=False)
    own = load_config("ppo", {"env": {"task_config": {"terminate_on_drop": False, "table": True}}})["env"]
    assert env_kwargs_for("grasp", None, "allegro", own)["config"] == dict(terminate_on_drop=False, table=True)
    assert env_kwargs_for("rotate", "x+", "allegro", load_config(
        "ppo", {"env": {"terminate_on_drop": {"rotate": True}}})["env"])["config"]["terminate_on_drop"] is True
    with pytest.raises(KeyError, match="env.terminate_on_drop.grsp"):
        load_config("ppo", {"env": {"terminate_on_drop": {"grsp": True}}})


@pytest.mark.parametrize("once", [True, False])
def test_training_log_counts_an_episode_success_as_the_protocol_does(once):
    """PPO's logged success per finished episode: for a ``success_once`` skill (rotate, translate) the
    success held at some step and nothing dropped, carried across batches; otherwise the flag at the
    episode's last step. Two envs, two batches of 3 steps: env 0 passes the threshold in batch 1 and
    slides back before its episode ends in batch 2; env 1 passes it and then drops (its success flag
    turns false at the drop)."""
    from types import SimpleNamespace
    from tensordict import TensorDict
    from unicross.rl.ppo import PPOTrainer

    def batch(succ, drop, done):
        t = lambda v, dt: torch.tensor(v, dtype=dt)[..., None]  # noqa: E731  [envs, T, 1]
        return TensorDict({"next": {"reward": torch.ones(2, 3, 1), "done": t(done, torch.bool),
                                    "info": {"success": t(succ, torch.bool), "drop": t(drop, torch.bool)}}},
                          batch_size=[2, 3])
    z = lambda dt: torch.zeros(2, 1, dtype=dt)  # noqa: E731
    me = SimpleNamespace(_success_once=once, _ep_return=z(torch.float32), _ep_reached=z(torch.bool),
                         _ep_dropped=z(torch.bool))
    first = PPOTrainer._episode_stats(me, batch([[0, 1, 0], [0, 1, 0]], [[0, 0, 0], [0, 0, 1]],
                                                [[0, 0, 0], [0, 0, 0]]))
    assert first["episodes"] == 0
    second = PPOTrainer._episode_stats(me, batch([[0, 0, 0], [0, 0, 0]], [[0, 0, 0], [0, 0, 0]],
                                                 [[0, 1, 0], [0, 1, 0]]))
    assert second["episodes"] == 2 and second["episode_return"] == 5.0
    assert second["success_rate"] == (0.5 if once else 0.0)
    assert not me._ep_reached.any() and not me._ep_dropped.any()  # reset with the episodes
