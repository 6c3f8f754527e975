"""What learning needs from the tasks and the trainer: an audited reward, bounded and finite
signals, varied and reproducible episodes, a PPO that starts near the zero action, and the
shipped grasp expert."""
import math
import gymnasium as gym
import pytest
import torch

import unicross  # noqa: F401
from unicross.audit import ascent, ascent_behaviours, audit, first_dip
from unicross.config import load_preset

ENV = dict(obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none", object_limit=1)


def test_grasp_audit_ranks_the_successful_grasp_first():
    rows = audit("grasp", limit=1, seeds=1, progress=False)
    assert rows[0].behaviour == "scripted" and rows[0].success >= 0.75
    ranked = [r.behaviour for r in rows]
    for lazy in ("hover", "zero", "close_only", "random"):  # every non-grasping behaviour earns less
        assert ranked.index(lazy) > ranked.index("descend_close")


@pytest.mark.parametrize("skill,axis,reference", [("rotate", "z+", "oracle"), ("translate", "z-", "oracle")])
def test_in_hand_audits_rank_the_successful_reference_first(skill, axis, reference):
    rows = audit(skill, axis, limit=1, seeds=1, progress=False)
    assert rows[0].behaviour == reference and rows[0].success > 0
    assert all(r.success <= rows[0].success for r in rows[1:])
    assert all(r.min_total > -1e3 for r in rows)  # bounded (discounted, scaled) even for random actions


def test_rotate_audit_pays_a_successful_gait_more_than_holding_still():
    """With our coefficients (the rotate success bonus), the episodes in which the shipped y- gait
    turns the object past the success angle earn more on average than any zero-action episode, and
    most of them each earn more (without the bonus, they earned less: configs/reward.yaml). Not every
    one: on one 2-core VM (2026-11-28) one of four successful episodes earned -1.68 against the
    zero action's best -0.98 (README "Choices": the rotate success term)."""
    rows = {r.behaviour: r for r in audit("rotate", "y-", limit=2, seeds=3, progress=False, only=["gait", "zero"])}
    won = [x for x, s in zip(rows["gait"].returns, rows["gait"].successes) if s]
    assert won, "the gait succeeded in none of these episodes (it did in 3-4 of 12 when this test was written)"
    best_still = max(rows["zero"].returns)
    assert sum(won) / len(won) > best_still
    assert sum(x > best_still for x in won) > len(won) / 2


def test_relocate_audit_ranks_following_the_target_first():
    """Following the interpolated target (the zero action) beats the naive baseline and holding
    still with our coefficients (the progress term; with the paper's, holding still ties)."""
    rows = audit("relocate", limit=1, seeds=2, progress=False, only=["follow", "naive", "stay"])
    assert [r.behaviour for r in rows][0] == "follow" and rows[0].success >= 0.75
    assert next(r for r in rows if r.behaviour == "stay").success == 0.0  # holding still never relocates


def test_grasp_audit_of_mano_pays_grasping_over_holding_the_wrist_down():
    """Training's grasp episodes end at a drop (the paper's termination, configs/ppo.yaml), and MANO's
    scripted grasp out-earns holding the wrist down against the lift (``hold_down``, which never lifts
    the object, so never drops it). Penalised to the end instead, MANO's failed lifts made holding down
    pay more on average, and PPO learned it (README "Grasp experts for other hands")."""
    rows = audit("grasp", hand="mano", limit=1, seeds=1, progress=False, only=["scripted", "hold_down"])
    assert [r.behaviour for r in rows] == ["scripted", "hold_down"]
    hold = rows[1]
    assert hold.success == 0.0 and hold.terms["drop"] == 0.0


def test_paper_reward_pays_hovering_more_than_grasping():
    """The measurement that forced the success term: with the paper's coefficients, hovering
    above the object out-earns a successful grasp (as PPO sees it: discounted, scaled)."""
    rows = audit("grasp", limit=1, seeds=1, progress=False, only=["scripted", "hover"],
                 ppo_overrides=load_preset("paper_reward"))
    assert [r.behaviour for r in rows] == ["hover", "scripted"]


def test_translate_audit_pays_sliding_the_object_out_more_than_holding_still():
    """Opening the fingers slides the object out along them (a physical translate z+): with our
    success bonus it out-earns holding still; with the paper's coefficients it did not (the
    measurement that set ``success.translate``)."""
    ours = audit("translate", "z+", limit=1, seeds=1, progress=False, only=["open", "zero"])
    assert [r.behaviour for r in ours] == ["open", "zero"] and ours[0].success > 0
    paper = audit("translate", "z+", limit=1, seeds=1, progress=False, only=["open", "zero"],
                  ppo_overrides=load_preset("paper_reward"))
    assert [r.behaviour for r in paper] == ["zero", "open"]


def test_translate_return_rises_on_the_way_to_opening_the_fingers():
    """PPO starts at the zero action: opening at a quarter of the reference's rate (no success yet)
    must already earn more than holding still. With the paper's r_motion weight it earned less
    (the object tilts and the fingers bend before the slide pays): the valley that set
    ``motion.translate``."""
    ours = ascent("translate", "z+", fractions=(0.0, 0.25), limit=2, seeds=1, progress=False)
    assert [r.behaviour for r in ours] == ["open@0", "open@0.25"] and first_dip(ours) is None
    paper = ascent("translate", "z+", fractions=(0.0, 0.25), limit=2, seeds=1, progress=False,
                   ppo_overrides=load_preset("paper_reward"))
    assert first_dip(paper) == "open@0.25"
    with pytest.raises(ValueError, match="no physical reference"):
        ascent_behaviours("rotate", "x+")


def test_random_rotate_returns_are_bounded_and_finite():
    env = gym.make("UniCross-Rotate-v1", axis="x+", config=dict(terminate_on_drop=False), **ENV)
    u = env.unwrapped
    g = torch.Generator().manual_seed(0)
    for seed in range(2):
        u.reset(seed=seed)
        total = 0.0
        for _ in range(int(u.episode_length[u.mode[0]])):
            _, r, _, _, info = u.step(torch.rand(1, u.hand_spec.dof, generator=g) * 2 - 1)
            assert torch.isfinite(r).all()
            total += float(r[0])
        assert total > -1e5
    env.close()


def test_nonfinite_step_is_zeroed_reported_and_ends_the_episode():
    env = gym.make("UniCross-Grasp-v1", **ENV)
    u = env.unwrapped
    u.reset(seed=0)
    u.rewards.coefficients("wrist_velocity")["w_vel"] = float("nan")
    obs, r, term, trunc, info = u.step(torch.zeros(1, u.hand_spec.dof))
    assert bool(info["nonfinite"][0]) and bool(trunc[0]) and float(r[0]) == 0.0
    env.close()


@pytest.mark.parametrize("env_id,kw", [("UniCross-Grasp-v1", {}), ("UniCross-Rotate-v1", {"axis": "y+"}),
                                       ("UniCross-Translate-v1", {"direction": "z-"})])
def test_unseeded_resets_differ_and_seeded_resets_repeat_the_start(env_id, kw):
    env = gym.make(env_id, randomize=True, **kw, **ENV)
    u = env.unwrapped

    def start(seed=None):
        obs, _ = u.reset(seed=seed)
        return torch.cat([obs["extra"]["hand"], obs["extra"]["goal"], u.obj.pose.raw_pose], -1)
    a = start(11)
    for _ in range(3):
        u.step(torch.rand(1, u.hand_spec.dof) * 2 - 1)
    b, c = start(), start()
    assert not torch.allclose(a, b) and not torch.allclose(b, c)
    assert torch.equal(start(11), a)
    env.close()


@pytest.mark.parametrize("env_id,kw", [("UniCross-Grasp-v1", {}), ("UniCross-Relocate-v1", {}),
                                       ("UniCross-Rotate-v1", dict(axis="x-")),
                                       ("UniCross-Translate-v1", dict(direction="z+")),
                                       ("UniCross-Relocate-v1", dict(object_limit=1, reconfiguration_freq=0))])
def test_seeded_episode_replays_exactly_with_randomisation_and_rebuilds(env_id, kw):
    """A seeded reset replays its whole episode (object, mass, friction, start, noise and
    perturbations, physics) whatever ran before it, in the same env or in a new one: on the full
    object set with scene rebuilds, and in an env that never rebuilds by itself (its mass and
    friction, drawn when the scene is built, come from the seed too)."""
    def make():
        return gym.make(env_id, **{**dict(randomize=True, reconfiguration_freq=4, obs_mode="state_dict",
                                          sim_backend="physx_cpu", render_backend="none"), **kw}).unwrapped

    def episode(u, seed=5, action_seed=1, steps=60):
        u.reset(seed=seed)
        g = torch.Generator().manual_seed(action_seed)
        out = []
        for _ in range(steps):
            obs, r, *_ = u.step((torch.rand(1, u.hand_spec.dof, generator=g) * 2 - 1) * 0.3)
            out.append(torch.cat([obs["extra"]["hand"], obs["extra"]["goal"], r[:, None]], -1))
        return torch.cat(out)
    u = make()
    for _ in range(3):  # unseeded episodes first: they move the rebuild cursor and the generators
        u.reset()
        u.step(torch.zeros(1, u.hand_spec.dof))
    first = episode(u)
    episode(u, seed=9, action_seed=3, steps=30)  # another seeded episode in between
    assert torch.equal(episode(u), first)
    u.close()
    other = make()  # a new env (its first scene built without a seed)
    assert torch.equal(episode(other), first)
    other.close()


def test_untrained_policy_acts_near_zero_and_normaliser_skips_nonfinite_rows():
    from tensordict import TensorDict
    from unicross.config import load_config
    from unicross.rl.models import make_models
    policy, value, norm = make_models(dict(hand=44, object=105, goal=55), 22, None, load_config("ppo")["model"])
    td = TensorDict(hand=torch.randn(64, 44), object=torch.randn(64, 105), goal=torch.randn(64, 55), batch_size=[64])
    assert policy.module[0](td.clone())["loc"].abs().max() < 0.05
    td["hand"][3, 0] = float("nan")
    assert norm.update({k: td[k] for k in ("hand", "object", "goal")}) == 63
    assert all(torch.isfinite(b).all() for b in norm.buffers())
    td["hand"][3, 0] = 0.0
    out = value(td.clone())
    assert torch.allclose(out["state_value"], value.value_norm(out["state_value_norm"]))


def test_the_rollout_acting_path_equals_the_actor_and_reads_the_weights_live():
    """``GaussianHead.acting_fn`` (what rollouts act with) gives the actor's (loc, scale) to rounding, with
    clipped features and a std floor; it follows in-place weight updates (shared-memory workers) and
    keeps the statistics it was taken with until a fresh one is taken."""
    from unicross.config import load_config
    from unicross.rl.models import make_models
    cfg = load_config("ppo")["model"]
    cfg["obs_std_min"] = 0.05
    dims = dict(hand=44, object=105, goal=55)
    policy, _, norm = make_models(dims, 22, None, cfg)
    head = policy.module[0].module
    g = torch.Generator().manual_seed(0)
    norm.update({k: torch.randn(300, d, generator=g) * 2 + 1 for k, d in dims.items()})
    with torch.no_grad():
        for p in head.parameters():
            p.copy_(torch.randn(p.shape, generator=g) / p.shape[-1] ** 0.5)
    x = [torch.randn(7, d, generator=g) * 6 for d in dims.values()]  # some features beyond the clip
    act = head.acting_fn()
    for a, b in zip(act(*x), head(*x)):
        assert torch.allclose(a, b, rtol=1e-5, atol=1e-5)  # a strided view may take another GEMM path
    with torch.no_grad():
        head.net.main[0].weight.mul_(2.0)  # an update in place
        norm.update({k: torch.randn(300, d, generator=g) * 5 for k, d in dims.items()})
    moved = act(*x)[0]
    assert not torch.allclose(moved, head(*x)[0], rtol=1e-3)  # the statistics were snapshotted
    assert torch.allclose(head.acting_fn()(*x)[0], head(*x)[0], rtol=1e-5, atol=1e-5)
    with torch.no_grad():
        head.net.main[0].weight.mul_(0.5)
    assert not torch.allclose(act(*x)[0], moved, rtol=1e-3)  # the weights are read live


def test_obs_std_floor_keeps_a_barely_varying_feature_off_the_clip_and_travels_with_the_checkpoint(tmp_path):
    """A feature that stayed still in the fitted data (std ~1e-4) reaches the clip at a 1 cm change
    without ``model.obs_std_min``; with a floor of 1e-2 it reads ~1, the rest unchanged; a saved
    policy rebuilds with its floor (old checkpoints, without the key, keep none)."""
    from unicross.config import load_config
    from unicross.rl.models import make_models
    from unicross.rl.policy_io import load_policy
    dims = dict(hand=4, object=3, goal=55)
    cfg = load_config("ppo")
    assert cfg["model"]["obs_std_min"] == 0.0
    data = {k: torch.randn(256, d) for k, d in dims.items()}
    data["hand"][:, 0] = 0.5 + 1e-4 * torch.randn(256)
    x = {k: v[:2].clone() for k, v in data.items()}
    x["hand"][:, 0] = 0.51
    outs = {}
    for floor in (0.0, 1e-2):
        cfg["model"]["obs_std_min"] = floor
        policy, _, norm = make_models(dims, 5, None, cfg["model"])
        norm.update(data)
        outs[floor] = norm("hand", x["hand"])
        path = tmp_path / f"p{floor}.pt"
        torch.save(dict(policy=policy.state_dict(), obs_dims=dims, n_act=5, hand="allegro", config=cfg, skill="grasp"), path)
        loaded, _ = load_policy(path)
        assert loaded.module[0].module.net.norm.std_min == floor
    assert outs[0.0][:, 0].abs().min() == 5.0  # clipped
    assert torch.allclose(outs[1e-2][:, 0], torch.full((2,), 1.0), atol=0.1)
    assert torch.allclose(outs[0.0][:, 1:], outs[1e-2][:, 1:])  # features that vary are untouched


@pytest.mark.parametrize("hand", ["allegro", "mano", "sharpa_wave"])
def test_shipped_grasp_expert_lifts_a_held_out_object(hand):
    """The shipped expert (unicross/checkpoints/<hand>/grasp.pt, by its shorthand) grasps and lifts
    a test object it never trained on, under the paper's grasp protocol; another hand's expert is
    refused before any simulation."""
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    policy, desc = E.resolve_policy(f"{hand}/grasp", hand)
    assert desc["skill"] == "grasp"
    # the first test object; for MANO, whose expert (made under 8 solver iterations) misses it in 3 of 3 under
    # 12, one it lifted in 3 of 3 trials of the report's cell under 12 (docs/runs/physics_settings section 4)
    name = "wrappable-box-test-103" if hand == "mano" else None
    obj = get_object_set("test-wrappable", limit=1)[:1] if name is None else \
        [o for o in get_object_set("test-wrappable") if o.name == name]
    trials = E.run_protocol("grasp", policy, obj, hand=hand, trials_per_object=3, seed=0, progress=False)
    # Allegro's expert lifts it 3 times of 3 here, MANO's and Sharpa Wave's at least once (82-94% held out),
    # the zero action never
    assert sum(t["success"] for t in trials) >= (2 if hand == "allegro" else 1)
    other = "mano" if hand == "allegro" else "allegro"
    with pytest.raises(ValueError, match=f"trained for hand {hand!r}, not {other!r}"):
        E.resolve_policy(f"{hand}/grasp", other)


@pytest.mark.parametrize("hand", ["allegro", "mano", "sharpa_wave"])
def test_shipped_relocate_expert_relocates_a_held_out_object(hand):
    """The shipped relocate expert (<hand>/relocate) carries a held test object to its goal pose
    under the paper's relocate protocol, refuses another hand, and is not a grasp policy."""
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    policy, desc = E.resolve_policy(f"{hand}/relocate", hand)
    assert desc["skill"] == "relocate"
    # the second test box: Sharpa Wave's expert turns the first one in its grasp in 2 of 3 trials (0.14-0.27
    # rad off the goal; 97.5% over the held-out cell), which the zero action does not
    obj = [o for o in get_object_set("test-wrappable") if o.name == "wrappable-box-test-101"]
    trials = E.run_protocol("relocate", policy, obj, hand=hand, trials_per_object=2, seed=0, progress=False)
    assert sum(t["success"] for t in trials) >= 1
    other = "mano" if hand == "allegro" else "allegro"
    with pytest.raises(ValueError, match=f"trained for hand {hand!r}, not {other!r}"):
        E.resolve_policy(f"{hand}/relocate", other)


def _shipped_and_zero(spec: str, skill: str, axis: str, objects, trials_per_object: int, hand: str = "allegro"):
    """(trials of the shipped checkpoint ``spec``, trials of the zero action) under the paper's
    protocol of ``skill`` about/along ``axis`` on ``objects`` with ``hand``; checks the checkpoint's mode first."""
    from unicross import evaluation as E
    policy, desc = E.resolve_policy(spec, hand)
    assert (desc["skill"], desc.get("axis")) == (skill, axis)
    kw = dict(trials_per_object=trials_per_object, seed=0, progress=False, axes=[axis], hand=hand)
    return E.run_protocol(skill, policy, objects, **kw), E.run_protocol(skill, E.zero_policy, objects, **kw)


@pytest.mark.parametrize("hand,axis,names,trials_per_object", [
    ("allegro", "z+", None, 2), ("sharpa_wave", "z+", None, 2),
    # Allegro's z- expert (a clone of a two-phase finger sequence, 84% of the report's test cell): its first
    # elongated test object, pulled in 5 of 5 trials there (docs/runs/translate_zm_reference/second_phase/clone_s0)
    ("allegro", "z-", None, 2),
    # Sharpa Wave's z- expert (a clone of a finger sequence searched under 12 solver iterations, 35% of the
    # report's test cell): two test objects it pulled in 1 and 2 of their first 3 trials there
    ("sharpa_wave", "z-", ["elongated-box-test-100", "elongated-cylinder-test-108"], 3)])
def test_shipped_translate_expert_translates_a_held_out_object(hand, axis, names, trials_per_object):
    """The shipped translate expert (<hand>/translate_<axis>) moves a held elongated test object along
    the fingers (z+: out toward the fingertips, z-: in toward the wrist) past the paper's threshold under
    the translate protocol, where the zero action moves none."""
    from unicross.objects import get_object_set
    objects = get_object_set("test-elongated", limit=1)[:1] if names is None else \
        [o for o in get_object_set("test-elongated") if o.name in names]
    trials, zero = _shipped_and_zero(f"{hand}/translate_{axis}", "translate", axis, objects,
                                     trials_per_object=trials_per_object, hand=hand)
    assert sum(t["success"] for t in trials) >= 1 and not any(t["success"] for t in zero)


def test_shipped_rotate_policy_turns_a_held_out_object():
    """The shipped rotate y- policy (allegro/rotate_y-: a network cloned from the scripted gait run
    without its stop, acting from the observation alone) turns a held test object past pi/2 about the
    hand's y- axis without dropping it, where the zero action turns none (two test objects, 3 trials
    each: in the recorded held-out evaluation, docs/runs/nostop/clone_y-_shipped/eval_test120, it
    turned the box in 3 of 3 trials and the cylinder in 2 of 3; the first two test objects, which this
    test used before, are on the edge: 1 of 6 there, 0 with the eager step math)."""
    from unicross.objects import get_object_set
    names = ("wrappable-box-test-105", "wrappable-cylinder-test-101")
    objects = [o for o in get_object_set("test", limit=20) if o.name in names]
    assert len(objects) == 2
    trials, zero = _shipped_and_zero("allegro/rotate_y-", "rotate", "y-", objects, trials_per_object=3)
    assert sum(t["success"] for t in trials) >= 1 and not any(t["success"] for t in zero)


@pytest.mark.parametrize("hand", ["allegro", "mano", "sharpa_wave"])
def test_shipped_student_is_distilled_for_every_shipped_expert_and_grasps_a_held_out_object(hand):
    """The shipped student (<hand>/student) was distilled from every shipped expert of its hand (Allegro:
    the ten modes; MANO: grasp, relocate; Sharpa Wave: grasp, relocate, translate z+ and z-), and the one network grasps and lifts a
    held-out test object under the paper's grasp protocol, where the zero action lifts none (first two
    test objects, one trial each)."""
    from unicross import formulation as F
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    from unicross.report import shipped
    from unicross.rl.policy_io import read_torch_file, resolve_checkpoint
    ck = read_torch_file(resolve_checkpoint(f"{hand}/student"), "checkpoint")
    experts = sorted(m for m in shipped(hand) if m in F.MODES)
    assert ck["skill"] == "multi" and sorted(ck["distilled_modes"]) == experts
    assert hand != "allegro" or experts == sorted(F.MODES)
    policy, _ = E.resolve_policy(f"{hand}/student", hand)
    objs = get_object_set("test", limit=1)[:2]
    kw = dict(trials_per_object=1, seed=0, progress=False, hand=hand)
    trials, zero = E.run_protocol("grasp", policy, objs, **kw), E.run_protocol("grasp", E.zero_policy, objs, **kw)
    assert sum(t["success"] for t in trials) >= 1 and not any(t["success"] for t in zero)


def test_every_shipped_expert_loads_as_a_teacher_of_its_own_mode_only():
    """Each shipped expert loads as DAgger's frozen teacher for its mode and is refused in the
    folder of another mode."""
    import pytest
    from unicross.report import CHECKPOINTS, shipped
    from unicross.rl.dagger import Teachers
    from unicross import formulation as F
    experts = {m: CHECKPOINTS / "allegro" / f"{m}.pt" for m in shipped("allegro") if m != "student"}
    assert set(experts) == set(F.MODES)  # every mode ships its best checkpoint, however weak (README)
    t = Teachers(experts, "cpu")
    assert t.modes == list(experts) and not any(p.requires_grad for p in t.parameters())
    with pytest.raises(ValueError, match="trained for mode"):
        Teachers({"translate_z-": experts["translate_z+"]}, "cpu")


def test_init_reference_starts_the_mean_at_the_physical_reference(tmp_path):
    """``model.init_reference``: the untrained policy's mean is the physical reference's constant
    action (translate z+: opening the fingers) at that fraction of its rate; a mode without a
    physical reference is refused before any simulation."""
    from unicross.audit import PHYSICAL_REFERENCES, reference_action
    from unicross.rl.ppo import PPOTrainer
    from unicross.robots.hand import load_hand
    over = dict(env=dict(num_envs=1, object_limit=1), collector=dict(total_frames=16, horizon=16),
                model=dict(init_reference=0.5), logging=dict(eval_trials=0, final_eval_trials=0))
    t = PPOTrainer(tmp_path / "tr", "translate", "z+", overrides=over, progress=False)
    try:
        want = reference_action("translate", "z+", load_hand("allegro"), 0.5)
        torch.testing.assert_close(t.algo.actor.net.main[-1].bias.detach(), want)
        rate = PHYSICAL_REFERENCES[("translate", "z+")][1]
        assert float(want[6:].abs().max()) == pytest.approx(abs(rate) * 0.5 / 0.1)  # allegro fingers: 0.1 rad
        assert float(want[:6].abs().max()) == 0.0
    finally:
        t.close()
    with pytest.raises(ValueError, match="no physical reference"):
        PPOTrainer(tmp_path / "rot", "rotate", "x+", overrides=over, progress=False)


def test_init_policy_starts_the_actor_from_a_policy_checkpoint(tmp_path):
    """``model.init_policy``: the untrained actor acts as the named policy (weights and observation
    statistics) with the configured exploration noise; a policy of another mode is refused before
    any simulation."""
    from unicross.rl.policy_io import load_policy, resolve_checkpoint
    from unicross.rl.ppo import PPOTrainer
    shipped = str(resolve_checkpoint("allegro/translate_z+"))
    over = dict(env=dict(num_envs=1, object_limit=1), collector=dict(total_frames=16, horizon=16),
                model=dict(init_policy=shipped, init_log_std=-2.0), logging=dict(eval_trials=0, final_eval_trials=0))
    t = PPOTrainer(tmp_path / "tr", "translate", "z+", overrides=over, progress=False)
    try:
        ref, ck = load_policy(shipped)
        g = torch.Generator().manual_seed(0)
        x = [torch.randn(4, ck["obs_dims"][k], generator=g) for k in ("hand", "object", "goal")]
        want, _ = ref.module[0].module(*x)
        got, scale = t.algo.actor(*x)
        torch.testing.assert_close(got, want)
        torch.testing.assert_close(scale[0], torch.full_like(scale[0], math.exp(-2.0)))
    finally:
        t.close()
    with pytest.raises(ValueError, match="this run trains"):
        PPOTrainer(tmp_path / "rot", "rotate", "x+", overrides=over, progress=False)


def test_init_policy_brings_its_input_floor(tmp_path):
    """A policy trained with an input floor (``model.obs_std_min``: the shipped rotate clones) starts a
    PPO run as itself: the run adopts the floor, whatever its configuration said, and acts as the
    loaded policy on inputs near its statistics (where a floor of 0 divides by ~1e-4 instead of 0.01).
    Fails without the adoption: the run kept its configured floor and started from another policy."""
    from unicross.rl.policy_io import load_policy, resolve_checkpoint
    from unicross.rl.ppo import PPOTrainer
    shipped = str(resolve_checkpoint("allegro/rotate_z+"))
    ref, ck = load_policy(shipped)
    assert ck["config"]["model"]["obs_std_min"] == 0.01  # the premise: the shipped clone has a floor
    over = dict(env=dict(num_envs=1, object_limit=1), collector=dict(total_frames=16, horizon=16),
                model=dict(init_policy=shipped, obs_std_min=0.0), logging=dict(eval_trials=0, final_eval_trials=0))
    t = PPOTrainer(tmp_path / "rz", "rotate", "z+", overrides=over, progress=False)
    try:
        assert t.algo.norm.std_min == 0.01 and t.cfg["model"]["obs_std_min"] == 0.01
        # the checkpoint records what the run started from (the tables call it PPO from a clone)
        assert t.state()["started_from"] == dict(policy=shipped, clone_of=ck["clone_of"])
        g = torch.Generator().manual_seed(0)
        norm = ref.module[0].module.net.norm
        x = [getattr(norm, f"{k}_mean") + 0.01 * torch.randn(4, ck["obs_dims"][k], generator=g)
             for k in ("hand", "object", "goal")]
        want, _ = ref.module[0].module(*x)
        got, _ = t.algo.actor(*x)
        torch.testing.assert_close(got, want)
    finally:
        t.close()


@pytest.mark.slow
def test_gait_clone_writes_a_policy_that_loads_and_logs_its_fresh_error(tmp_path):
    """benchmarks/gait_clone.py end to end at its smallest (one object per group, one round): a
    policy checkpoint the evaluation loads, a log whose network round has ``fresh_mse``, and a held-out
    file (``--heldout``) with the trials `unicross eval` gives that checkpoint."""
    import json
    import subprocess
    import sys
    from pathlib import Path
    from unicross.evaluation import resolve_policy, run_protocol
    from unicross.objects import get_object_set
    script = Path(__file__).resolve().parent.parent / "benchmarks" / "gait_clone.py"
    out = tmp_path / "clone"
    subprocess.run([sys.executable, str(script), "--gait", "allegro/rotate_y-,tracking=phase,lookahead=1.5",
                    "--limit", "1", "--trials", "1", "--rounds", "1", "--workers", "1", "--heldout", "1",
                    "--out", str(out)], check=True, timeout=900)
    rows = [json.loads(line) for line in (out / "log.jsonl").read_text().splitlines()]
    assert rows[0]["actor"] == "gait" and rows[1]["actor"] == "network" and rows[1]["fresh_mse"] >= 0
    policy, desc = resolve_policy(str(out / "policy.pt"), "allegro")
    assert desc["kind"] != "gait"
    held = json.loads((out / "heldout.json").read_text())
    trials = run_protocol("rotate", policy, get_object_set("test", limit=1), trials_per_object=3, seed=0,
                          axes=["y-"], progress=False)
    assert held["n"] == len(trials) == len(held["trials"])
    key = lambda t: (t["object"], t["trial"])  # noqa: E731
    assert [(key(t), t["success"], t["steps"]) for t in sorted(held["trials"], key=key)] == \
        [(key(t), t["success"], t["steps"]) for t in sorted(trials, key=key)]
