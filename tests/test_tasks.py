"""The ManiSkill tasks: spaces, determinism, state round trips, targets, contacts, drops, ablations."""

import pytest
import torch

from conftest import make
from unicross import formulation as F
from unicross.geometry import quat_angle, quat_apply, quat_inv, quat_mul, quat_to_axis_angle

TASKS = [("UniCross-Grasp-v1", {}), ("UniCross-Relocate-v1", {}), ("UniCross-Rotate-v1", {"axis": "x-"}),
         ("UniCross-Translate-v1", {"direction": "z-"}), ("UniCross-MultiSkill-v1", {})]
OBS = 2 * 22 + 5 * 21 + 55  # s^h + s^o + g for the floating Allegro


@pytest.mark.parametrize("task,kw", TASKS)
def test_reset_and_random_steps(task, kw, grasp_file):
    env = make(task, grasp_file, **kw)
    obs, info = env.reset(seed=1)
    assert obs.shape == (1, OBS)
    assert env.action_space.shape == (1, 22) and env.unwrapped.single_action_space.shape == (22,)
    g = torch.Generator().manual_seed(0)
    for _ in range(5):
        obs, r, term, trunc, info = env.step(torch.rand(22, generator=g) * 2 - 1)
        assert torch.isfinite(obs).all() and torch.isfinite(r).all()
    u = env.unwrapped
    sd = u.get_obs(unflattened=True)
    assert sd["extra"]["goal"].shape == (1, 55)
    assert sd["extra"]["hand"].shape == (1, 44)
    assert {k: v.shape[-1] for k, v in sd["extra"]["object"].items()} == {"contact": 21, "force": 21, "distance": 63}
    for k in ("success", "drop", "fail", "rotation", "translation", "relocate_pos_err", "reward_track"):
        assert k in info
    env.close()


def test_state_dict_obs_mode(grasp_file):
    env = make("UniCross-Rotate-v1", grasp_file, obs_mode="state_dict")
    obs, _ = env.reset(seed=0)
    assert set(obs) == {"agent", "extra"} and set(obs["extra"]) == {"hand", "object", "goal"}
    assert obs["extra"]["goal"].shape == (1, F.GOAL_DIM) == (1, 55)
    env.close()


@pytest.mark.parametrize("task,kw", [("UniCross-MultiSkill-v1", {}), ("UniCross-Grasp-v1", {})])
def test_thin_step_equals_maniskills_generic_step(task, kw, grasp_file):
    """The thin step (state observation, dense reward) returns what BaseEnv.step's generic assembly
    returns from the same episode: observation (ManiSkill's flattening of the observation dict),
    reward, terminated, truncated and info, bit for bit, with randomisation (noise, pushes) live,
    for the state and the state_dict observation modes."""
    def run(thin, obs_mode="state"):
        env = make(task, grasp_file, randomize=True, obs_mode=obs_mode, **kw)
        u = env.unwrapped
        assert u._thin_step
        u._thin_step = thin
        out = [u.reset(seed=5)]
        g = torch.Generator().manual_seed(2)
        for _ in range(12):
            out.append(u.step((torch.rand(1, 22, generator=g) * 2 - 1) * 0.5))
        env.close()
        return out
    thin, generic = run(True), run(False)
    thin_dict, generic_dict = run(True, "state_dict"), run(False, "state_dict")
    from mani_skill.utils.common import flatten_state_dict
    for i, (a, b, c, d) in enumerate(zip(thin, generic, thin_dict, generic_dict)):
        assert torch.equal(a[0], b[0]), f"observation differs at step {i}"
        for x, y in ((c[0], d[0]), (c[0]["extra"]["object"], d[0]["extra"]["object"])):
            assert x.keys() == y.keys()
        assert torch.equal(flatten_state_dict(c[0], use_torch=True), flatten_state_dict(d[0], use_torch=True))
        assert torch.equal(a[0], flatten_state_dict(d[0], use_torch=True)), f"state_dict differs at step {i}"
        for x, y, z in zip(a[1:-1], b[1:-1], c[1:-1]):
            assert torch.equal(x, y) and torch.equal(x, z)
        info_a, info_b = a[-1], b[-1]
        assert info_a.keys() == info_b.keys()
        for k in info_a:
            assert torch.equal(torch.as_tensor(info_a[k]), torch.as_tensor(info_b[k])), f"info[{k}] at step {i}"


def test_nan_action_raises():
    env = make("UniCross-Grasp-v1")
    env.reset(seed=0)
    a = torch.zeros(22)
    for bad in (float("nan"), float("inf"), -float("inf")):
        a[3] = bad
        with pytest.raises(ValueError, match="NaN or inf"):
            env.step(a)
    a[:] = 3.0e38  # finite, however large: clamped, not refused
    env.step(a)
    with pytest.raises(ValueError):
        env.step(torch.zeros(21))
    env.close()


@pytest.mark.parametrize("task,kw", [TASKS[0], TASKS[2]])
def test_same_seed_same_observations(task, kw, grasp_file):
    def run():
        env = make(task, grasp_file, **kw)
        out = [env.reset(seed=7)[0]]
        g = torch.Generator().manual_seed(3)
        for _ in range(4):
            out.append(env.step(torch.rand(22, generator=g) * 2 - 1)[0])
        env.close()
        return torch.stack(out)
    a, b = run(), run()
    assert torch.equal(a, b)
    # different seeds give different starts (randomisation is live)
    env = make(task, grasp_file, **kw)
    assert not torch.equal(env.reset(seed=7)[0], env.reset(seed=8)[0])
    env.close()


@pytest.mark.parametrize("task,kw", [TASKS[0], TASKS[3]])
def test_state_round_trip(task, kw, grasp_file):
    env = make(task, grasp_file, **kw)
    u = env.unwrapped
    env.reset(seed=2)
    g = torch.Generator().manual_seed(1)
    for _ in range(3):
        obs, *_ = env.step(torch.rand(22, generator=g) * 2 - 1)
    state = u.get_state()
    saved_obs = u.get_obs()
    nxt, *_ = env.step(torch.zeros(22))
    for _ in range(3):
        env.step(torch.rand(22, generator=g) * 2 - 1)
    u.set_state(state)
    assert torch.allclose(u.get_obs(), saved_obs, atol=1e-5)
    # the dict form too, and stepping on from the restored state reproduces the next obs
    u.set_state_dict(u.get_state_dict())
    assert torch.allclose(u.get_obs(), saved_obs, atol=1e-5)
    # the task state is one TensorDict of batch [N], in its own dtypes, loadable as it is
    td = u.task_state()
    assert td.batch_size == torch.Size([1]) and set(td.keys()) == set(u.TASK_STATE)
    assert td["ever_dropped"].dtype == torch.bool and td["targets"].shape == (1, 21)
    env.step(torch.zeros(22))
    u.load_task_state(td)
    assert torch.equal(u.task_state()["targets"], td["targets"])
    env.close()


def test_invalid_arguments_fail_fast_with_valid_values():
    with pytest.raises(ValueError, match="x\\+"):
        make("UniCross-Rotate-v1", axis="w+")
    with pytest.raises(ValueError, match="z\\+"):
        make("UniCross-Translate-v1", direction="x+")
    with pytest.raises(ValueError, match="allegro"):
        make("UniCross-Grasp-v1", hand="nohand")
    with pytest.raises(ValueError, match="train-wrappable"):
        make("UniCross-Grasp-v1", objects="no-such-set")
    with pytest.raises(ValueError, match="grasp"):
        make("UniCross-MultiSkill-v1", modes=["fly"])
    with pytest.raises(FileNotFoundError, match="unicross grasps"):
        make("UniCross-Relocate-v1", grasp_dataset="/nonexistent/grasps.pt")
    with pytest.raises(ValueError, match="no object"):
        make("UniCross-Rotate-v1", objects="train-elongated")  # rotate needs wrappable objects


def test_multiskill_pairs_are_valid(tiny_objects, grasp_file):
    env = make("UniCross-MultiSkill-v1", grasp_file)
    u = env.unwrapped
    valid = set()
    for oi, o in enumerate(u.object_specs):  # wrappable: grasp, relocate, 6 rotations; elongated: grasp, relocate, 2 translations
        for mi, m in enumerate(F.MODES):
            skill = F.mode_skill(m)
            if not (skill == "rotate" and o.category != "wrappable") and not (skill == "translate" and o.category != "elongated"):
                valid.add((oi, mi))
    assert len(valid) == 2 * 8 + 2 * 4 and set(u._pairs) == valid
    assert u.mode.shape == (1,) and u.mode.dtype == torch.long
    env.close()


@pytest.mark.parametrize("order", ["sequential", "balanced"])
def test_objects_without_grasps_serve_only_the_grasp_mode(tiny_objects, grasp_file, order):
    from unicross.grasps import GraspSet
    gs = GraspSet.load(grasp_file)
    gone = gs.object_names.index(tiny_objects[0].name)  # the wrappable box
    partial = GraspSet(gs.hand, gs.object_names, gs.data[gs.data["object_id"] != gone], gs.source)
    env = make("UniCross-MultiSkill-v1", None, grasp_dataset=partial, config={"pair_order": order})
    u = env.unwrapped
    modes_of_box = {F.MODES[mi] for oi, mi in u._pairs if u.object_names[oi] == tiny_objects[0].name}
    assert modes_of_box == {"grasp"}
    assert sum(F.mode_skill(F.MODES[mi]) == "rotate" for _, mi in u._pairs) > 0  # the wrappable cylinder still rotates
    env.close()


def test_pair_walk_spreads_every_window_over_modes_and_objects():
    from tasks.base import pair_walk
    # a set listed as the real ones are: 6 boxes, then 6 cylinders; two modes valid for all of them, one for
    # the last 4 only (a shorter list, as rotate's and translate's are)
    per_mode = [list(range(12)), list(range(12)), list(range(8, 12))]
    walk = pair_walk(per_mode, [0, 1, 5], "balanced")
    assert set(walk) == {(o, m) for lst, m in zip(per_mode, [0, 1, 5]) for o in lst}
    assert len(walk) == 3 * 12  # the shorter list cycles: every mode in every round
    for start in range(len(walk) - 3):
        assert sorted(m for _, m in walk[start:start + 3]) == [0, 1, 5]
    for mi in (0, 1):  # the first half of a mode's pairs is no longer one shape group
        first = [o for o, m in walk if m == mi][:6]
        assert any(o < 6 for o in first) and any(o >= 6 for o in first)
    assert pair_walk(per_mode, [0, 1, 5], "balanced") == walk  # the same walk in every process
    # the order before: objects in the set's order, the shorter list ending early
    seq = pair_walk(per_mode, [0, 1, 5], "sequential")
    assert seq[:3] == [(0, 0), (0, 1), (8, 5)] and seq[-2:] == [(11, 0), (11, 1)] and len(seq) == 28
    with pytest.raises(ValueError, match="balanced"):
        pair_walk(per_mode, [0, 1, 5], "random")


# ----------------------------------------------------------------------------- target semantics
def _step(env, n, seed=0):
    g = torch.Generator().manual_seed(seed)
    for _ in range(n):
        env.step((torch.rand(22, generator=g) * 2 - 1) * 0.3)


def test_rotate_targets(grasp_file):
    env = make("UniCross-Rotate-v1", grasp_file, axis="y+")
    u = env.unwrapped
    env.reset(seed=0)
    init = u.init_rel.clone()
    w_dt = u.cfg["motion"]["omega_max"] * u.control_dt
    for k in range(4):
        _step(env, 1, seed=k)
        t, c = u.targets, u.cur_rel
        assert torch.allclose(t.x_hr, init.x_hr) and torch.allclose(t.q_hr, init.q_hr)   # wrist fixed
        assert torch.allclose(t.x_oh, init.x_oh) and torch.allclose(t.x_or, init.x_or)   # position fixed
        rv = quat_to_axis_angle(quat_mul(t.q_oh, quat_inv(c.q_oh)))                       # q̂_oh = R(ωΔt, d) q_oh
        assert torch.allclose(rv, torch.tensor([[0.0, w_dt, 0.0]]), atol=1e-5)
        assert torch.allclose(u.axis, torch.tensor([[0.0, 1.0, 0.0]]))
        assert quat_angle(t.q_or, quat_mul(c.q_hr, t.q_oh)).item() < 1e-4               # q̂_or from the current wrist
    env.close()


def test_translate_targets(grasp_file):
    env = make("UniCross-Translate-v1", grasp_file, direction="z+")
    u = env.unwrapped
    env.reset(seed=0)
    init = u.init_rel.clone()
    v_dt = u.cfg["motion"]["v_max"] * u.control_dt
    for k in range(4):
        _step(env, 1, seed=k)
        t, c = u.targets, u.cur_rel
        assert torch.allclose(t.x_oh - c.x_oh, torch.tensor([[0.0, 0.0, v_dt]]), atol=1e-6)
        assert torch.allclose(t.q_oh, init.q_oh) and torch.allclose(t.q_or, init.q_or)
        assert torch.allclose(t.x_hr, init.x_hr) and torch.allclose(t.q_hr, init.q_hr)
        assert torch.allclose(t.x_or, c.x_hr + quat_apply(c.q_hr, t.x_oh), atol=1e-6)
    env.close()


def test_relocate_targets_interpolate_to_final(grasp_file):
    env = make("UniCross-Relocate-v1", grasp_file)
    u = env.unwrapped
    env.reset(seed=0)
    init = u.init_rel.clone()
    v_dt = u.cfg["motion"]["relocate_v"] * u.control_dt
    w_dt = u.cfg["motion"]["relocate_omega"] * u.control_dt
    for k in range(4):
        _step(env, 1, seed=k)
        t, c = u.targets, u.cur_rel
        step = t.x_or - c.x_or
        to_final = u.final_x_or - c.x_or
        assert torch.allclose(step.norm(), torch.minimum(torch.tensor(v_dt), to_final.norm()), atol=1e-5)
        assert torch.nn.functional.cosine_similarity(step, to_final).item() > 0.9999
        ang_step = quat_angle(c.q_or, t.q_or)
        ang_total = quat_angle(c.q_or, u.final_q_or)
        assert torch.allclose(ang_step, torch.minimum(torch.tensor(w_dt), ang_total), atol=1e-4)
        assert torch.allclose(t.x_oh, init.x_oh) and torch.allclose(t.q_oh, init.q_oh)     # fixed in hand
        # the hand target realises the object target with the current object-in-hand pose
        assert torch.allclose(t.x_hr + quat_apply(t.q_hr, c.x_oh), t.x_or, atol=1e-5)
    env.close()


def test_grasp_targets():
    env = make("UniCross-Grasp-v1")
    u = env.unwrapped
    env.reset(seed=0)
    init = u.init_rel.clone()
    for k in range(4):
        _step(env, 1, seed=k)
        t, c = u.targets, u.cur_rel
        assert torch.allclose(t.x_or, init.x_or) and torch.allclose(t.q_or, init.q_or)     # object fixed in root
        assert torch.equal(t.x_hr, c.x_hr) and torch.equal(t.q_hr, c.q_hr)                  # hand free
        assert torch.equal(t.q_oh, c.q_oh)
        assert torch.equal(t.x_oh, torch.zeros_like(t.x_oh))                                # towards the palm point
        d = -c.x_oh / c.x_oh.norm()
        assert torch.allclose(u.axis, d, atol=1e-6)                                         # object centre -> hand origin
    env.close()


def test_action_mapping_residuals():
    env = make("UniCross-Grasp-v1", randomize=False)
    u = env.unwrapped
    env.reset(seed=0)
    a = torch.zeros(1, 22)
    a[0, 0] = 1.0
    a[0, 10] = -1.0
    prev = u.command.clone()
    wrist_ref = F.wrist_reference(u.targets)
    env.step(a)
    expected = prev.clone()
    expected[:, :6] = wrist_ref
    expected = torch.clamp(expected + u.action_scale * a, u.q_lower, u.q_upper)
    assert torch.allclose(u.command, expected, atol=1e-6)
    assert torch.allclose(u.command[0, 0], wrist_ref[0, 0] + u.hand_spec.action_scale["wrist_translation"])
    # fingers: residual on the previous command, clamped at the joint limit
    for _ in range(40):
        env.step(a)
    assert torch.allclose(u.command[0, 10], u.q_lower[10])
    env.close()


# ----------------------------------------------------------------------------- contacts and drops
def test_contact_flags_follow_pressing():
    from unicross.scripted_grasp import ScriptedGrasp
    env = make("UniCross-Grasp-v1", randomize=False, config=dict(grasp=dict(lift_after=None)))
    u = env.unwrapped
    env.reset(seed=0)
    sd = u.get_obs(unflattened=True)["extra"]["object"]
    assert sd["contact"].sum() == 0 and sd["force"].sum() == 0  # hovering: nothing touches
    policy = ScriptedGrasp(u)
    for _ in range(policy.t_lift):
        env.step(policy())
    sd = u.get_obs(unflattened=True)["extra"]["object"]
    c, f = sd["contact"][0], sd["force"][0]
    dist = sd["distance"][0].view(-1, 3).norm(dim=-1)
    assert c.sum() >= 2                                  # fingers press the object
    assert torch.all((c > 0) == (f > u.cfg["contact_force_threshold"]))
    assert torch.all(f[c == 0] <= u.cfg["contact_force_threshold"])
    assert torch.all(dist[c > 0] < 0.03)                 # pressing links are at the surface
    # the sensor's per-link sums equal a plain per-point loop over every contact, bodies told apart by entity
    links = {l._bodies[0].entity.per_scene_id: i for i, l in enumerate(u.contact_links)}
    obj_id, want = u.obj._bodies[0].entity.per_scene_id, torch.zeros(len(links), 3, dtype=torch.float64)
    for contact in u.scene.px.get_contacts():
        ids = [b.entity.per_scene_id for b in contact.bodies]
        for sign, (mine, other) in ((-1.0, ids), (1.0, ids[::-1])):
            if mine == obj_id and other in links:
                for point in contact.points:
                    want[links[other]] += sign * torch.as_tensor(point.impulse, dtype=torch.float64)
    # the pose read equals SAPIEN's positions and quaternions, body by body
    pos, quat = u.sensor.poses()
    for i, comp in enumerate(u.sensor._components):
        pose = comp.entity_pose
        assert pos[0, i].tolist() == torch.as_tensor(pose.p, dtype=torch.float32).tolist()
        assert quat[0, i].tolist() == torch.as_tensor(pose.q, dtype=torch.float32).tolist()
    got = u.sensor.contact_forces()[0]
    assert float(want.norm()) > 0
    torch.testing.assert_close(got.double(), want / u.scene.px.timestep, rtol=1e-5, atol=1e-6)
    # move the object away from the hand: after the next physics step no link is in contact
    obj = u.obj.pose
    u.obj.set_pose(obj.__class__.create_from_pq(obj.p + torch.tensor([0.4, 0.0, 0.0]), obj.q))
    env.step(torch.zeros(22))
    sd = u.get_obs(unflattened=True)["extra"]["object"]
    assert sd["contact"].sum() == 0
    env.close()


def test_drop_terminates(grasp_file):
    env = make("UniCross-Rotate-v1", grasp_file)
    u = env.unwrapped
    env.reset(seed=0)
    _, _, term, _, info = env.step(torch.zeros(22))
    assert not term.any()
    pose = u.obj.pose
    u.obj.set_pose(pose.__class__.create_from_pq(pose.p + torch.tensor([0.0, 0.0, -0.4]), pose.q))
    _, r, term, _, info = env.step(torch.zeros(22))
    assert term.all() and info["drop"].all() and info["fail"].all() and not info["success"].any()
    assert info["reward_drop"].item() == pytest.approx(u.reward_cfg["reg"]["w_drop"])


# ----------------------------------------------------------------------------- ablation switches
def test_ablation_switches(grasp_file):
    abl = dict(no_target_obs=True, no_distance=True, no_contact=True, no_track_reward=True, no_target_action=True)
    env = make("UniCross-Relocate-v1", grasp_file, config=dict(ablation=abl))
    u = env.unwrapped
    env.reset(seed=0)
    prev = u.command.clone()
    obs, r, *_ , info = env.step(torch.zeros(22))
    sd = u.get_obs(unflattened=True)["extra"]
    assert torch.all(sd["goal"][:, -21:] == 0)
    assert torch.all(sd["object"]["distance"] == 0) and torch.all(sd["object"]["contact"] == 0)
    assert torch.all(sd["object"]["force"] == 0)
    assert info["reward_track"].item() == 0.0
    assert torch.allclose(u.command[:, :6], prev[:, :6])   # wrist reference = previous command
    env.close()
    base = make("UniCross-Relocate-v1", grasp_file)
    base.reset(seed=0)
    *_, info = base.step(torch.zeros(22))
    assert info["reward_track"].item() != 0.0
    assert base.unwrapped.get_obs(unflattened=True)["extra"]["goal"][:, -21:].abs().sum() > 0
    base.close()


def test_reward_terms_use_config_coefficients(grasp_file):
    env = make("UniCross-Grasp-v1", reward_config=dict(contact=dict(grasp=dict(w_dis=0.0, w_con=0.0, w_f=0.0))))
    env.reset(seed=0)
    *_, info = env.step(torch.zeros(22))
    assert info["reward_contact"].item() == 0.0
    env.close()
    env = make("UniCross-Grasp-v1")
    env.reset(seed=0)
    *_, info = env.step(torch.zeros(22))
    assert info["reward_contact"].item() < 0  # hovering: -w_dis * distance dominates
    env.close()


def test_grasp_lift_phase_raises_the_wrist_at_the_set_speed():
    env = make("UniCross-Grasp-v1", randomize=False, config=dict(grasp=dict(lift_after=2, lift_speed=0.2)))
    u = env.unwrapped
    env.reset(seed=0)
    z = []
    for _ in range(12):
        env.step(torch.zeros(22))
        z.append((u.root_p + quat_apply(u.root_q, u.cur_rel.x_hr))[0, 2].item())
    rise = z[-1] - z[1]
    # 10 lifting steps at 0.2 m/s * 0.05 s: ~0.1 m (the position-controlled wrist lags a little)
    assert 0.05 < rise < 0.11
    env.close()


def test_drop_without_termination_when_switched_off(grasp_file):
    env = make("UniCross-Rotate-v1", grasp_file, config=dict(terminate_on_drop=False))
    u = env.unwrapped
    env.reset(seed=0)
    pose = u.obj.pose
    u.obj.set_pose(pose.__class__.create_from_pq(pose.p + torch.tensor([0.0, 0.0, -0.4]), pose.q))
    _, _, term, _, info = env.step(torch.zeros(22))
    assert info["drop"].all() and not term.any() and info["reward_drop"].item() < 0
    env.close()
