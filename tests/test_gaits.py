"""Scripted finger gaits (unicross.gaits): the gait's targets, the choice of gait from a search log,
and the policy's stop once the mode's threshold is passed; on a stand-in env, no simulator."""
import json
import math
from types import SimpleNamespace

import pytest
import torch

from unicross import formulation as F
from unicross.config import load_config
from unicross.gaits import NPAR, best_gait, gait_targets, make_gait_policy

pytestmark = pytest.mark.unit


def test_zero_gait_keeps_the_start_command_and_shapes_broadcast():
    q0 = torch.randn(3, 16)
    assert torch.equal(gait_targets([0.0] * NPAR, 7, q0), q0)
    p = torch.rand(NPAR) * 2 - 1
    one = gait_targets(p, 5, q0[0])
    assert one.shape == (16,) and torch.allclose(gait_targets(p, 5, q0)[0], one)
    period = 6 + 30 * (float(p[24]) + 1) / 2
    assert torch.allclose(gait_targets(p, 5, q0), gait_targets(p, 5 + period, q0), atol=1e-5)  # periodic


def _write(path, rows):
    path.write_text("".join(json.dumps(r) + "\n" for r in rows))


def test_best_gait_prefers_the_selection_and_applies_the_amplitude(tmp_path):
    meta = dict(amplitude=0.5)
    rows = [dict(meta=meta, p=[1.0] * NPAR, score=0.9),
            dict(meta=meta, p=[0.2] * NPAR, score=0.1),
            dict(meta=meta, selection=True, p=[0.2] * NPAR, score=0.1, success=0.7),
            dict(meta=meta, selection=True, p=[1.0] * NPAR, score=0.9, success=0.4)]
    _write(tmp_path / "log.jsonl", rows)
    p, row = best_gait(str(tmp_path / "log.jsonl"))
    assert row["success"] == 0.7
    assert torch.allclose(p[:24], torch.full((24,), 0.1)) and float(p[24]) == pytest.approx(0.2)
    _write(tmp_path / "search.jsonl", rows[:2])
    assert best_gait(str(tmp_path / "search.jsonl"))[1]["score"] == 0.9
    _write(tmp_path / "random.jsonl", [dict(meta=meta, p=[0.0] * NPAR, r=[[0.0] * 8])])
    with pytest.raises(ValueError, match="not a gait search log"):
        best_gait(str(tmp_path / "random.jsonl"))


def _stand_in_env(n: int, mode: str, axis):
    return SimpleNamespace(hand_spec=SimpleNamespace(dof=22, name="allegro"), num_envs=n, device="cpu",
                           elapsed_steps=torch.zeros(n, dtype=torch.int32), command=torch.zeros(n, 22),
                           action_scale=torch.full((22,), 0.1), mode=torch.full((n,), F.MODES.index(mode)),
                           cfg=load_config("task"), axis=torch.tensor(axis, dtype=torch.float32).expand(n, 3),
                           obj_angvel_h=torch.zeros(n, 3), obj_vel_h=torch.zeros(n, 3), control_dt=0.05)


def test_the_policy_runs_the_gait_until_the_object_has_turned_past_the_angle_then_holds(tmp_path):
    g = torch.Generator().manual_seed(0)
    _write(tmp_path / "log.jsonl", [dict(meta=dict(amplitude=1.0), p=(torch.rand(NPAR, generator=g) * 2 - 1).tolist(),
                                         score=1.0)])
    policy = make_gait_policy(str(tmp_path / "log.jsonl"))
    u = _stand_in_env(2, "rotate_y-", [0.0, -1.0, 0.0])
    angle = u.cfg["success"]["rotate_angle"]
    steps_to_pass = math.floor(angle / 0.05) + 1  # 1 rad/s about -y (env 0), none for env 1
    for t in range(steps_to_pass + 3):
        u.elapsed_steps[:] = t
        a = policy(None, u)
        assert a.shape == (2, 22) and torch.all(a[:, :6] == 0)  # the wrist holds still
        moving = a[:, 6:].abs().sum(-1) > 0
        assert bool(moving[1])  # never turned: the gait goes on
        assert bool(moving[0]) == (t < steps_to_pass)
        u.command[:, 6:] += a[:, 6:] * u.action_scale[6:]
        u.obj_angvel_h[0] = torch.tensor([0.0, -1.0, 0.0])
    u.elapsed_steps[:] = 0  # a reset starts the gait again
    assert bool((policy(None, u)[0, 6:].abs().sum() > 0))


def test_without_the_stop_the_gait_keeps_cycling_past_the_angle(tmp_path):
    """``stop=0`` (or a log searched with ``gait_search.py --no-stop``): no privileged stop, the gait goes on
    for the whole episode after the object has passed the success angle; ``stop=1`` in the spec restores it."""
    g = torch.Generator().manual_seed(0)
    p = (torch.rand(NPAR, generator=g) * 2 - 1).tolist()
    _write(tmp_path / "log.jsonl", [dict(meta=dict(amplitude=1.0), p=p, score=1.0)])
    _write(tmp_path / "nostop.jsonl", [dict(meta=dict(amplitude=1.0, no_stop=True), p=p, score=1.0)])
    policies = {name: make_gait_policy(spec) for name, spec in
                (("stop", str(tmp_path / "log.jsonl")), ("spec", f"{tmp_path / 'log.jsonl'},stop=0"),
                 ("log", str(tmp_path / "nostop.jsonl")), ("log_stop", f"{tmp_path / 'nostop.jsonl'},stop=1"))}
    envs = {name: _stand_in_env(1, "rotate_y-", [0.0, -1.0, 0.0]) for name in policies}
    steps_to_pass = math.floor(envs["stop"].cfg["success"]["rotate_angle"] / 0.05) + 1
    for t in range(steps_to_pass + 3):
        moving = {}
        for name, policy in policies.items():
            u = envs[name]
            u.elapsed_steps[:] = t
            a = policy(None, u)
            moving[name] = bool(a[0, 6:].abs().sum() > 0)
            u.command[:, 6:] += a[:, 6:] * u.action_scale[6:]
            u.obj_angvel_h[0] = torch.tensor([0.0, -1.0, 0.0])
        assert moving["spec"] and moving["log"]  # past the angle too
        assert moving["stop"] == moving["log_stop"] == (t < steps_to_pass)
    with pytest.raises(ValueError, match="stop must be 0 or 1"):
        make_gait_policy(f"{tmp_path / 'log.jsonl'},stop=2")


def test_gait_policies_refuse_other_hands(tmp_path):
    from unicross.evaluation import resolve_policy
    _write(tmp_path / "log.jsonl", [dict(meta=dict(skill="rotate", refine="z+"), p=[0.0] * NPAR, score=0.0)])
    with pytest.raises(ValueError, match="a gait for hand 'allegro', not 'sharpa_wave'"):
        resolve_policy(f"gait:{tmp_path / 'log.jsonl'}", "sharpa_wave")
    policy, desc = resolve_policy(f"gait:{tmp_path / 'log.jsonl'}", "allegro")
    assert desc["kind"] == "gait" and desc["mode"] == "rotate_z+"


def test_a_gait_is_evaluated_on_its_own_mode_only(tmp_path, capsys):
    from unicross.cli import main
    _write(tmp_path / "log.jsonl", [dict(meta=dict(skill="rotate", refine="y-"), p=[0.0] * NPAR, score=0.0)])
    for extra in ([], ["--axis", "x+"], ["--axis", "y-,x+"]):
        assert main(["eval", "--policy", f"gait:{tmp_path / 'log.jsonl'}", "--protocol", "rotate", *extra,
                     "--out", str(tmp_path / "ev")]) != 0
        assert "is a gait for rotate_y-: evaluate it with --protocol rotate --axis y-" in capsys.readouterr().err
    assert not (tmp_path / "ev").exists()


def test_phase_tracking_follows_the_cycle_from_wherever_the_fingers_are(tmp_path):
    """``tracking="phase"``: the target is ``lookahead`` steps past the point of the cycle nearest
    the command. A hand on the cycle at step t is sent to the clock's target of step t + lookahead,
    whatever the env's clock says (a clock gait would send it back to its own step); the action
    depends on the command, not on the clock; wrong settings are refused."""
    from unicross.gaits import gait_offsets
    g = torch.Generator().manual_seed(1)
    p = (torch.rand(NPAR, generator=g) * 2 - 1).tolist()
    p[24] = -1.0  # a period of 6 control steps: grid points at whole and half steps
    _write(tmp_path / "log.jsonl", [dict(meta=dict(amplitude=1.0), p=p, score=1.0)])
    policy = make_gait_policy(str(tmp_path / "log.jsonl"), tracking="phase", lookahead=1.0, grid=2)
    clock = make_gait_policy(str(tmp_path / "log.jsonl"))
    u = _stand_in_env(1, "rotate_y-", [0.0, -1.0, 0.0])
    u.action_scale = torch.full((22,), 10.0)  # no clamp: the action is the whole move to the target
    q0 = u.command[:, 6:].clone()
    policy(None, u)  # step 0 fixes q0
    clock(None, u)
    for t_hand, t_clock in ((2, 5), (3.5, 1)):
        u.command[:, 6:] = q0 + gait_offsets(p, torch.tensor(t_hand))
        u.elapsed_steps[:] = t_clock
        move = policy(None, u)[:, 6:] * 10.0
        want = gait_offsets(p, torch.tensor(t_hand + 1.0)) - gait_offsets(p, torch.tensor(t_hand))
        torch.testing.assert_close(move[0], want, atol=1e-5, rtol=0)
        assert not torch.allclose(clock(None, u)[:, 6:] * 10.0, move, atol=1e-3)  # the clock's target differs
    with pytest.raises(ValueError, match="tracking"):
        make_gait_policy(str(tmp_path / "log.jsonl"), tracking="nearest")
    # a gait searched with phase tracking (its log's meta: gait_search.py --tracking phase) runs with it
    _write(tmp_path / "phase.jsonl", [dict(meta=dict(amplitude=1.0, tracking="phase", lookahead=1.0), p=p, score=1.0)])
    searched = make_gait_policy(str(tmp_path / "phase.jsonl"), grid=2)
    u.elapsed_steps[:] = 0
    u.command[:, 6:] = q0
    searched(None, u)
    u.command[:, 6:] = q0 + gait_offsets(p, torch.tensor(2.0))
    u.elapsed_steps[:] = 5
    want = gait_offsets(p, torch.tensor(3.0)) - gait_offsets(p, torch.tensor(2.0))
    torch.testing.assert_close(searched(None, u)[0, 6:] * 10.0, want, atol=1e-5, rtol=0)


def test_gait_options_ride_in_the_spec(tmp_path):
    """``GAIT,tracking=phase,lookahead=1.5``: what ``unicross eval --policy gait:...`` and
    ``collector.teacher`` pass on; unknown keys and bad values are refused."""
    from unicross.gaits import resolve_gait, split_gait_spec
    assert split_gait_spec("allegro/rotate_y-,tracking=phase,lookahead=1.5,grid=4") == \
        ("allegro/rotate_y-", dict(tracking="phase", lookahead=1.5, grid=4))
    assert resolve_gait("allegro/rotate_y-,tracking=phase") == resolve_gait("allegro/rotate_y-")
    for bad in ("allegro/rotate_y-,speed=2", "allegro/rotate_y-,lookahead=fast", "allegro/rotate_y-,tracking"):
        with pytest.raises(ValueError, match="gait 'allegro/rotate_y-,"):
            split_gait_spec(bad)
    with pytest.raises(ValueError, match="tracking must be one of"):
        make_gait_policy("allegro/rotate_y-,tracking=nearest")
    u = _stand_in_env(1, "rotate_y-", [0.0, -1.0, 0.0])
    u.command[:, 6:] = 0.3  # off the cycle: the two trackings pick different targets
    u.elapsed_steps[:] = 0
    phase = make_gait_policy("allegro/rotate_y-,tracking=phase,lookahead=1.5")(None, u)
    assert torch.equal(phase, make_gait_policy("allegro/rotate_y-", tracking="phase", lookahead=1.5)(None, u))
    assert not torch.equal(phase, make_gait_policy("allegro/rotate_y-,tracking=clock")(None, u))
    # the shipped y- gait was searched with phase tracking at lookahead 1.5 (its meta): that is how it runs by default
    assert torch.equal(phase, make_gait_policy("allegro/rotate_y-")(None, u))


def test_a_reversed_gait_runs_the_same_loop_backwards_and_is_a_gait_for_the_opposite_direction(tmp_path):
    """``reverse_gait``: offsets at t are the original's at -t (every finger, distal loop included),
    reversing twice gives the gait back, and ``reverse=1`` names the opposite direction as its mode
    and moves the fingers the other way round on a stand-in env."""
    from unicross.gaits import gait_offsets, resolve_gait, reverse_gait
    g = torch.Generator().manual_seed(1)
    for _ in range(5):
        p = torch.rand(NPAR, generator=g) * 2 - 1
        q = reverse_gait(p)
        t = torch.arange(0, 60, 0.25)
        assert torch.allclose(gait_offsets(q, t), gait_offsets(p, -t), atol=1e-5)
        assert not torch.allclose(gait_offsets(q, t), gait_offsets(p, t), atol=1e-3)
        assert torch.allclose(reverse_gait(q), p, atol=1e-6)
        assert q.min() >= -1 and q.max() <= 1
    forward = make_gait_policy("allegro/rotate_y-,tracking=clock")  # the clock: its first target is the gait's at t = 1
    backward = make_gait_policy("allegro/rotate_y-,reverse=1,tracking=clock")
    assert forward.gait_row["mode"] == "rotate_y-"
    assert backward.gait_row["mode"] == "rotate_y+" and backward.gait_row["reversed_from"] == "rotate_y-"
    (tmp_path / "reversed.jsonl").write_text(json.dumps(backward.gait_row) + "\n")  # the row an eval records
    assert torch.allclose(best_gait(str(tmp_path / "reversed.jsonl"))[0], torch.tensor(backward.gait_row["p"]), atol=1e-6)
    u = _stand_in_env(1, "rotate_y+", [0.0, 1.0, 0.0])
    u.elapsed_steps[:] = 0
    a_f, a_b = forward(None, u), backward(None, u)  # from the start command, the first step of each loop
    p = best_gait(resolve_gait("allegro/rotate_y-"))[0]
    want_b = gait_offsets(p, torch.tensor(-1.0)) / 0.1  # the first target: the forward gait's at t = -1
    assert torch.allclose(a_b[0, 6:], want_b.clamp(-1, 1), atol=1e-5) and not torch.allclose(a_f, a_b)
    with pytest.raises(ValueError, match="reverse must be 0 or 1"):
        make_gait_policy("allegro/rotate_y-,reverse=2")


def _guarded_and_plain(tmp_path, seed: int, **guard):
    """(gait p, the gait with ``guard`` options, the plain gait, two stand-in y- envs of Allegro with unclamped
    actions for them, the closing direction): what the guard tests step side by side."""
    from robots.hand import load_hand
    from unicross.scripted_grasp import closing_direction
    g = torch.Generator().manual_seed(seed)
    _write(tmp_path / "log.jsonl", [dict(meta=dict(amplitude=1.0), p=(torch.rand(NPAR, generator=g) * 2 - 1).tolist(),
                                         score=1.0)])
    p = best_gait(str(tmp_path / "log.jsonl"))[0]
    guarded = make_gait_policy(str(tmp_path / "log.jsonl"), **guard)
    plain = make_gait_policy(str(tmp_path / "log.jsonl"))
    u, v = _stand_in_env(1, "rotate_y-", [0.0, -1.0, 0.0]), _stand_in_env(1, "rotate_y-", [0.0, -1.0, 0.0])
    u.hand_spec = v.hand_spec = load_hand("allegro")
    u.action_scale = v.action_scale = torch.full((22,), 10.0)  # no clamp
    return p, guarded, plain, u, v, closing_direction(u.hand_spec)


def _same_for(steps: int, guarded, plain, u, v) -> None:
    """Steps the guarded gait on ``u`` and the plain one on ``v`` from step 0, checking that they act alike."""
    for t in range(steps):
        u.elapsed_steps[:] = v.elapsed_steps[:] = t
        a, b = guarded(None, u), plain(None, v)
        torch.testing.assert_close(a, b)
        u.command[:, 6:] += a[:, 6:] * 10.0
        v.command[:, 6:] += b[:, 6:] * 10.0


def test_the_guard_pauses_the_gait_and_tightens_while_too_few_links_touch(tmp_path):
    """``guard=K``: with fewer than K links in contact the clock gait stands still and the fingers close
    along the closing direction by GUARD_RATE a step (at most guard_max); with enough contact it is
    the plain gait, its clock counting only the steps it ran."""
    from unicross.gaits import GUARD_RATE, gait_offsets
    p, guarded, plain, u, v, closing = _guarded_and_plain(tmp_path, 2, guard=2, guard_max=0.05)
    contact = torch.zeros(1, 16)
    u._obs_parts = dict(contact=contact)
    contact[0, :3] = 1.0  # three links touch: the plain gait
    _same_for(3, guarded, plain, u, v)
    contact[0, 1:] = 0.0  # one link: the gait pauses at its clock 3 and closes the grasp, up to guard_max
    for t, tight in ((3, GUARD_RATE), (4, 2 * GUARD_RATE), (5, 0.05), (6, 0.05)):
        u.elapsed_steps[:] = t
        u.command[:, 6:] += guarded(None, u)[:, 6:] * 10.0
        torch.testing.assert_close(u.command[0, 6:], gait_offsets(p, torch.tensor(3.0)) + tight * closing, atol=1e-5, rtol=0)
    contact[0, :3] = 1.0  # contact back: the gait goes on from its clock 4, around the tightened grasp
    u.elapsed_steps[:] = 7
    u.command[:, 6:] += guarded(None, u)[:, 6:] * 10.0
    torch.testing.assert_close(u.command[0, 6:], gait_offsets(p, torch.tensor(4.0)) + 0.05 * closing, atol=1e-5, rtol=0)
    with pytest.raises(ValueError, match="guard"):
        make_gait_policy(str(tmp_path / "log.jsonl"), guard=-1)


def test_the_drift_guard_tightens_while_the_object_is_off_its_place_then_lets_the_gait_go_on(tmp_path):
    """``drift=D``: while the object is more than D from its target position in the hand, the clock gait stands
    still and the fingers close by GUARD_RATE a step; once the tightening has reached guard_max the gait goes on
    around the tightened grasp although the object stays off its place (a drift persists). Close to its place it
    is the plain gait."""
    from unicross.gaits import GUARD_RATE, gait_offsets
    p, guarded, plain, u, v, closing = _guarded_and_plain(tmp_path, 3, drift=0.02, guard_max=0.05)
    u._obs_parts = dict(contact=torch.ones(1, 16))  # every link touches: only the drift can trigger
    u.cur_rel, u.targets = SimpleNamespace(x_oh=torch.zeros(1, 3)), SimpleNamespace(x_oh=torch.zeros(1, 3))
    _same_for(3, guarded, plain, u, v)
    u.cur_rel.x_oh[0, 0] = 0.03  # 3 cm off its place: the gait pauses at its clock 3 and closes, up to guard_max
    for t, tight in ((3, GUARD_RATE), (4, 2 * GUARD_RATE), (5, 0.05)):
        u.elapsed_steps[:] = t
        u.command[:, 6:] += guarded(None, u)[:, 6:] * 10.0
        torch.testing.assert_close(u.command[0, 6:], gait_offsets(p, torch.tensor(3.0)) + tight * closing, atol=1e-5, rtol=0)
    u.elapsed_steps[:] = 6  # still off its place, fully tightened: the gait goes on from its clock 4
    u.command[:, 6:] += guarded(None, u)[:, 6:] * 10.0
    torch.testing.assert_close(u.command[0, 6:], gait_offsets(p, torch.tensor(4.0)) + 0.05 * closing, atol=1e-5, rtol=0)
    with pytest.raises(ValueError, match="drift"):
        make_gait_policy("allegro/rotate_y-,drift=-0.01")


def test_a_gait_layout_follows_the_hand_and_keeps_allegros_gaits():
    """Allegro's layout read from its description is the built-in one (its shipped gaits move the same joints);
    Sharpa Wave's five fingers give 31 numbers that move only its named gait joints, flexing along the
    closing direction with a positive bias; a gait of another hand's length is refused."""
    from unicross.robots.hand import load_hand
    from unicross.gaits import ALLEGRO_LAYOUT, gait_layout, gait_offsets, layout_of
    assert gait_layout(load_hand("allegro")) == ALLEGRO_LAYOUT and ALLEGRO_LAYOUT.npar == NPAR
    spec = load_hand("sharpa_wave")
    layout = layout_of("sharpa_wave")
    assert layout.npar == 31 and layout.n_joints == len(spec.finger_joints) == 22
    p = torch.zeros(31)
    p[5::6] = 1.0  # every finger's bias, no motion
    off = gait_offsets(p, torch.tensor(3.0), layout=layout)
    moved = {spec.finger_joints[i] for i in torch.nonzero(off).flatten().tolist()}
    named = {j for js in spec.gait_joints.values() for j in js[1:]}  # flexion joints take the bias
    assert moved == named
    closing = torch.from_numpy(spec.closing_deltas())
    assert torch.all(off[closing > 0] > 0)
    with pytest.raises(ValueError, match="not one for hand 'sharpa_wave'"):
        gait_offsets(torch.zeros(NPAR), torch.tensor(1.0), layout=layout)
    with pytest.raises(ValueError, match="gait_joints"):
        type(spec)(**{**spec.__dict__, "gait_joints": {"index": ["index_PIP", "thumb_IP", "x"]}})


def test_a_gait_runs_only_on_the_hand_it_was_searched_for(tmp_path):
    from unicross.evaluation import resolve_policy
    _write(tmp_path / "log.jsonl", [dict(meta=dict(skill="rotate", refine="y-", hand="sharpa_wave"), p=[0.0] * 31,
                                         score=0.0)])
    policy, desc = resolve_policy(f"gait:{tmp_path / 'log.jsonl'}", "sharpa_wave")
    assert desc["mode"] == "rotate_y-"
    with pytest.raises(ValueError, match="a gait for hand 'sharpa_wave', not 'allegro'"):
        resolve_policy(f"gait:{tmp_path / 'log.jsonl'}", "allegro")
    u = _stand_in_env(1, "rotate_y-", [0.0, -1.0, 0.0])  # an Allegro stand-in
    with pytest.raises(ValueError, match="cannot run hand 'allegro'"):
        policy(None, u)
    _write(tmp_path / "short.jsonl", [dict(meta=dict(skill="rotate", refine="y-", hand="sharpa_wave"), p=[0.0] * NPAR,
                                           score=0.0)])
    with pytest.raises(ValueError, match="not one for hand 'sharpa_wave'"):
        make_gait_policy(str(tmp_path / "short.jsonl"))


def test_every_shipped_gait_loads_for_its_own_hand_only():
    from unicross.evaluation import resolve_policy
    from unicross.gaits import SHIPPED_DIR, shipped_gaits
    hands = sorted(p.name for p in SHIPPED_DIR.iterdir() if (p / "gaits").is_dir())
    assert "allegro" in hands and "sharpa_wave" in hands
    for hand in hands:
        for mode, spec in shipped_gaits(hand).items():
            policy, desc = resolve_policy(f"gait:{spec}", hand)
            assert desc["mode"] == mode and policy.gait_row["hand"] == hand
            other = "allegro" if hand != "allegro" else "sharpa_wave"
            with pytest.raises(ValueError, match=f"a gait for hand '{hand}', not '{other}'"):
                resolve_policy(f"gait:{spec}", other)
