"""The lean collector: worker processes act with the main process's current weights, store the
log-probabilities the PPO loss recomputes, and keep episode boundaries as TorchRL's GAE reads them."""
import copy

import pytest
import torch
from torchrl.data import Bounded

from unicross.rl import collector as C
from unicross.rl.collector import LeanCollector, make_collector, one_thread, update_threads, usable_cores
from unicross.rl.models import make_models

R_ID = "UniCross-Rotate-v1"
KW = dict(object_limit=1, reconfiguration_freq=1, config={"terminate_on_drop": False})  # episodes end at 64 steps


def _models(c):
    policy, _, norm = make_models(c.dims, c.n_act, Bounded(-1.0, 1.0, (c.n_act,)),
                                  dict(action_init_scale=0.01, init_log_std=-1.5))
    return policy, norm


def _check_batch(policy, data):
    """Stored loc/scale/log-prob are what the main process's policy gives now."""
    with torch.no_grad():
        obs = data.select("hand", "object", "goal")
        loc, scale = policy.module[0].module(obs["hand"], obs["object"], obs["goal"])
        logp = policy.get_dist(obs).log_prob(data["action"])
    torch.testing.assert_close(data["loc"], loc, atol=1e-5, rtol=1e-5)
    torch.testing.assert_close(data["scale"], scale)
    torch.testing.assert_close(data["action_log_prob"], logp, atol=1e-4, rtol=1e-5)


@pytest.mark.parametrize("num_envs", [1, 2])
def test_workers_act_with_current_weights(num_envs):
    c = LeanCollector("UniCross-Grasp-v1", KW, num_envs=num_envs, horizon=70, seed=3)
    try:
        policy, norm = _models(c)
        c.set_actor(policy.module[0].module)
        data = c.collect()
        assert data.shape == (num_envs, 70)
        _check_batch(policy, data)
        # an in-place change in the main process (as the optimiser and the statistics make) is
        # what the workers act with in the next batch
        with torch.no_grad():
            policy.module[0].module.net.main[-1].bias.add_(0.3)
            norm.update({k: data[k] for k in ("hand", "object", "goal")})
        data2 = c.collect()
        _check_batch(policy, data2)
        assert (data2["loc"] - data["loc"]).abs().mean() > 0.1
        # grasp episodes are 64 steps: step 63 ends each env's first episode (truncated), the next
        # step starts a fresh one whose observation differs from the stored terminal one
        done = data["next", "done"][..., 0]
        assert done[:, 63].all() and not done[:, :63].any()
        assert data["next", "truncated"][:, 63].all()
        assert not torch.equal(data["hand"][:, 64], data["next", "hand"][:, 63])
        assert torch.equal(data["hand"][:, 1:63], data["next", "hand"][:, :62])
        if num_envs == 2:  # envs are seeded differently
            assert not torch.equal(data["hand"][0, 0], data["hand"][1, 0])
    finally:
        c.close()


def test_correlated_noise_is_ar1_with_the_marginal_log_prob():
    """collector.noise_correlation: the noise (action - loc) / scale is AR(1) in time with lag-one
    correlation rho within an episode, white with rho 0, and the stored log-probability is the
    per-step Gaussian's (the marginal), which the PPO loss recomputes."""
    lag1 = {}
    for rho in (0.0, 0.9):
        c = LeanCollector("UniCross-Grasp-v1", KW, num_envs=1, horizon=64, seed=5, noise_correlation=rho)
        try:
            policy, _ = _models(c)
            c.set_actor(policy.module[0].module)
            data = c.collect()
            _check_batch(policy, data)
            eps = ((data["action"] - data["loc"]) / data["scale"])[0]  # [T, n_act], one episode
            assert abs(float(eps.std()) - 1.0) < 0.15
            lag1[rho] = float(torch.corrcoef(torch.stack([eps[1:].flatten(), eps[:-1].flatten()]))[0, 1])
        finally:
            c.close()
    assert abs(lag1[0.0]) < 0.1 and abs(lag1[0.9] - 0.9) < 0.05, lag1
    with pytest.raises(ValueError, match="noise_correlation"):
        make_collector("UniCross-Grasp-v1", KW, 1, 8, 0, "physx_cpu", noise_correlation=1.0)


def test_one_thread_holds_one_thread_and_restores_the_count():
    before = torch.get_num_threads()
    torch.set_num_threads(2)
    try:
        with pytest.raises(KeyError):
            with one_thread():
                assert torch.get_num_threads() == 1
                raise KeyError("the count comes back on errors too")
        assert torch.get_num_threads() == 2
    finally:
        torch.set_num_threads(before)


def test_update_threads_share_the_cores_among_live_runs(tmp_path, monkeypatch):
    import subprocess
    import sys
    monkeypatch.setattr(C, "RUNS_DIR", tmp_path / "runs")
    assert C.concurrent_runs() == 1 and update_threads(None) == usable_cores()
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        C.register_run()
        for name in (str(dead.pid), str(live.pid), "not-a-pid"):
            (C.RUNS_DIR / name).touch()
        assert C.concurrent_runs() == 2  # this process and the live one
        assert update_threads(None) == max(1, usable_cores() // 2)
    finally:
        live.kill()
        live.wait()
    assert C.concurrent_runs() == 1
    assert update_threads(1) == 1
    for bad in (0, -2, 1.5, "2", True):
        with pytest.raises(ValueError, match="update_threads"):
            update_threads(bad)


def test_trainers_refuse_bad_update_threads_before_simulating(tmp_path):
    from unicross.rl.ppo import PPOTrainer
    with pytest.raises(ValueError, match="update_threads"):
        PPOTrainer(tmp_path / "run", skill="grasp", overrides={"optim": {"update_threads": 0}}, progress=False)


def test_worker_errors_are_raised_in_the_main_process():
    with pytest.raises(RuntimeError, match="env worker 0"):
        LeanCollector("UniCross-Grasp-v1", dict(KW, objects="no-such-set"), num_envs=2, horizon=4)


def test_evaluation_in_the_workers_equals_one_process():
    """The trainer's held-out evaluation runs split over the env workers; the trials are those of
    one process running them all."""
    from unicross.rl.ppo import evaluation_shard
    c = LeanCollector("UniCross-Grasp-v1", KW, num_envs=2, horizon=4, seed=0)
    try:
        policy, _ = _models(c)
        c.set_actor(policy.module[0].module)
        kw = dict(skill="grasp", objects="test", limit=1, trials_per_object=1, seed=2, hand="allegro", axis=None,
                  ablation=None)
        split = [t for part in c.map_shards(evaluation_shard, **kw) for t in part]
    finally:
        c.close()
    whole = evaluation_shard(policy.module[0].module, shard=None, **kw)
    assert len(whole) == 4 and sorted(split, key=lambda t: t["object"]) == sorted(whole, key=lambda t: t["object"])


def test_overlapped_workers_act_with_their_own_copy_until_synced():
    """collector.overlap: the workers' actor is a copy that follows the learner's only at
    sync_actor(), so a batch started before an update is the old weights' whatever the update does
    meanwhile; an evaluation while a batch is in flight keeps that batch and runs the current weights."""
    from unicross.rl.ppo import evaluation_shard
    c = LeanCollector("UniCross-Grasp-v1", KW, num_envs=2, horizon=8, seed=3)
    try:
        policy, _ = _models(c)
        actor = policy.module[0].module
        c.set_actor(actor, own_copy=True)
        old = copy.deepcopy(policy)
        c.start()
        with pytest.raises(RuntimeError, match="pending"):
            c.start()
        with pytest.raises(RuntimeError, match="being collected"):
            c.sync_actor()
        with torch.no_grad():  # the learner's update, during the batch
            actor.net.main[-1].bias.add_(0.3)
        data = c.finish()
        _check_batch(old, data)
        _check_batch(old, c.collect())  # not synced: still the old weights
        c.sync_actor()
        _check_batch(policy, c.collect())
        with torch.no_grad():
            actor.net.main[-1].bias.add_(-0.6)
        c.start()  # in flight with the weights before that change
        kw = dict(skill="grasp", objects="test", limit=1, trials_per_object=1, seed=2, hand="allegro", axis=None,
                  ablation=None)
        split = [t for part in c.map_shards(evaluation_shard, **kw) for t in part]
        assert c.pending
        kept = c.finish()
        assert kept.shape == (2, 8) and not c.pending
        with pytest.raises(RuntimeError, match="without start"):
            c.finish()
        _check_batch(policy, c.collect())  # the evaluation synced the copy
    finally:
        c.close()
    whole = evaluation_shard(actor, shard=None, **kw)
    assert sorted(split, key=lambda t: t["object"]) == sorted(whole, key=lambda t: t["object"])
    one = LeanCollector("UniCross-Grasp-v1", KW, num_envs=1, horizon=4, seed=0)
    try:  # one env in the main process (a learner on the GPU): its copy too follows only at sync_actor()
        one.set_actor(actor, own_copy=True)
        with torch.no_grad():
            actor.net.main[-1].bias.add_(0.3)
        assert not torch.equal(one._shared.net.main[-1].bias, actor.net.main[-1].bias)
        one.sync_actor()
        assert torch.equal(one._shared.net.main[-1].bias, actor.net.main[-1].bias)
        with torch.no_grad():
            actor.net.main[-1].bias.add_(-0.3)
        one.map_shards(evaluation_shard, **kw)  # an evaluation runs the learner's current weights
        assert torch.equal(one._shared.net.main[-1].bias, actor.net.main[-1].bias)
    finally:
        one.close()


def test_update_device_is_checked_before_any_simulation(tmp_path):
    """optim.update_device: null is the envs' device; "auto" the GPU only where torch sees one; a GPU
    that is not there, or a CPU update of GPU envs, is refused with what to set."""
    from unicross.rl.collector import resolve_update_device
    assert resolve_update_device(None, "physx_cpu") == torch.device("cpu")
    assert resolve_update_device("cpu", "physx_cpu") == torch.device("cpu")
    assert resolve_update_device("auto", "physx_cpu").type == ("cuda" if torch.cuda.is_available() else "cpu")
    with pytest.raises(ValueError, match="must be null"):
        resolve_update_device("tpu", "physx_cpu")
    with pytest.raises(ValueError, match="must be null"):
        resolve_update_device("gpu please", "physx_cpu")
    with pytest.raises(ValueError, match="physx_cuda"):
        resolve_update_device("cpu", "physx_cuda")
    if not torch.cuda.is_available():
        with pytest.raises(ValueError, match="no CUDA device"):
            resolve_update_device("cuda", "physx_cpu")
        from unicross.rl.ppo import PPOTrainer
        with pytest.raises(ValueError, match="no CUDA device"):  # by the trainer, before its env workers start
            PPOTrainer(tmp_path / "run", "grasp", progress=False, overrides={"optim": {"update_device": "cuda"}})


def test_state_on_cpu_keeps_module_metadata():
    from unicross.rl.runner import on_cpu
    m = torch.nn.Linear(2, 3)
    sd = m.state_dict()
    out = on_cpu(dict(policy=sd, optim={"state": {0: {"step": torch.tensor(3.0)}}, "param_groups": [{"lr": 1.0}]}))
    assert out["policy"]._metadata == sd._metadata and torch.equal(out["policy"]["weight"], sd["weight"])
    assert out["optim"]["param_groups"] == [{"lr": 1.0}] and float(out["optim"]["state"][0]["step"]) == 3.0
    torch.nn.Linear(2, 3).load_state_dict(out["policy"])


@pytest.mark.slow
def test_ray_env_actors_collect_what_local_workers_collect():
    """The same run on a local Ray cluster (loopback): the env actors act with the main process's
    current weights and give the batches of the local worker processes, bit for bit."""
    ray = pytest.importorskip("ray")
    from unicross.rl.ray_collector import RayCollector
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    local = LeanCollector("UniCross-Grasp-v1", KW, num_envs=2, horizon=20, seed=5)
    remote = RayCollector("UniCross-Grasp-v1", KW, num_envs=2, horizon=20, seed=5, address="local")
    try:
        policy, norm = _models(local)
        local.set_actor(policy.module[0].module)
        remote.set_actor(policy.module[0].module)
        for _ in range(2):
            a, b = local.collect(), remote.collect()
            _check_batch(policy, b)
            for k in ("action", "loc", ("next", "reward"), ("next", "hand"), ("next", "info", "reward_contact")):
                assert torch.equal(a[k], b[k]), k
            with torch.no_grad():  # an update between batches reaches both
                policy.module[0].module.net.main[-1].bias.add_(0.3)
                norm.update({k: a[k] for k in ("hand", "object", "goal")})
    finally:
        local.close()
        remote.close()
        ray.shutdown()


class _ZeroActor(torch.nn.Module):
    def forward(self, hand, obj, goal):
        loc = torch.zeros(hand.shape[0], 22)
        return loc, torch.full_like(loc, 0.1)


def _gait_rollout_and_twin(actor, residual: bool, horizon: int = 6, seed: int = 5):
    """A 6-step rollout of the y- gait teacher (``residual``: the env takes gait + actor), the env
    kwargs, and a generator over a twin env reset alike: ``(t, twin env, the gait's label in its state)`` per step;
    the caller steps the twin. The twin is closed when the generator is exhausted."""
    import gymnasium as gym
    from unicross.config import load_config
    from unicross.rl.ppo import env_kwargs_for
    kw = dict(env_kwargs_for("rotate", "y-", "allegro", load_config("ppo")["env"]), object_limit=1)
    c = LeanCollector(R_ID, kw, num_envs=1, horizon=horizon, seed=seed, deterministic=True,
                      teacher="allegro/rotate_y-", residual=residual)
    try:
        c.set_actor(actor)
        data = c.collect()
    finally:
        c.close()

    def twin():
        env = gym.make(R_ID, render_backend="none", obs_mode="state_dict", num_envs=1, sim_backend="physx_cpu", **kw)
        try:
            u = env.unwrapped
            u.reset(seed=seed)
            gait = C.make_teacher("allegro/rotate_y-")
            for t in range(horizon):
                yield t, u, gait(u)
        finally:
            env.close()

    return data, kw, twin()


def test_a_gait_teacher_labels_every_collected_state():
    """``collector.teacher``: the batch's ``teacher_action`` is what the gait, run alongside on an
    identical env that takes the same actions, gives in each collected state."""
    data, _, twin = _gait_rollout_and_twin(_ZeroActor(), residual=False)
    for t, u, label in twin:
        torch.testing.assert_close(data["teacher_action"][:, t], label)
        u.step(data["action"][:, t])
    assert data["teacher_action"][:, :, 6:].abs().max() > 0.05  # the gait moves the fingers
    assert torch.equal(data["action"], torch.zeros_like(data["action"]))


def test_teacher_settings_are_refused_before_simulating(tmp_path):
    with pytest.raises(ValueError, match="is a gait for rotate_y-"):
        C.check_teacher("allegro/rotate_y-", "rotate", "z+", "physx_cpu")
    with pytest.raises(ValueError, match="physx_cpu"):
        C.check_teacher("allegro/rotate_y-", "rotate", "y-", "physx_cuda")
    with pytest.raises(FileNotFoundError, match="gait not found"):
        C.check_teacher("allegro/rotate_q", "rotate", "y-", "physx_cpu")
    from unicross.rl.ppo import PPOTrainer
    with pytest.raises(ValueError, match="needs collector.teacher"):
        PPOTrainer(tmp_path / "r", skill="rotate", axis="y-", overrides={"loss": {"teacher_coef": 1.0}})
    assert not (tmp_path / "r" / "checkpoint.pt").exists()
    base = {"model": {"base_policy": "allegro/rotate_y-"}}
    with pytest.raises(ValueError, match="model.base_policy=allegro/rotate_y- is a gait for rotate_y-"):
        PPOTrainer(tmp_path / "r", skill="rotate", axis="z+", overrides=base)
    with pytest.raises(ValueError, match="leave loss.teacher_coef at 0"):
        PPOTrainer(tmp_path / "r", skill="rotate", axis="y-", overrides=dict(base, loss={"teacher_coef": 1.0}))
    with pytest.raises(ValueError, match="differ"):
        PPOTrainer(tmp_path / "r", skill="rotate", axis="y-",
                   overrides=dict(base, collector={"teacher": "allegro/rotate_y-,tracking=phase"}))
    with pytest.raises(ValueError, match="acts on top of base policy None"):  # a plain network cannot start a residual run
        PPOTrainer(tmp_path / "r", skill="rotate", axis="y-",
                   overrides={"model": {"base_policy": "allegro/rotate_y-", "init_policy": "allegro/rotate_y-"}})
    assert not (tmp_path / "r" / "checkpoint.pt").exists()


class _ConstActor(torch.nn.Module):
    """A mean of 0.3 on the first finger joints and -0.4 on the last, whatever the state."""
    def forward(self, hand, obj, goal):
        loc = torch.zeros(hand.shape[0], 22)
        loc[:, 6:10], loc[:, -4:] = 0.3, -0.4
        return loc, torch.full_like(loc, 0.1)


def test_a_residual_rollout_steps_the_env_with_the_gait_plus_the_network():
    """``model.base_policy``: the env takes clip(gait + network action); the batch stores the
    network's action (PPO's ratio is the network's) and the gait's in ``teacher_action``. A twin env
    stepped by hand with clip(gait + action) sees the same observations."""
    data, kw, twin = _gait_rollout_and_twin(_ConstActor(), residual=True)
    for t, u, label in twin:
        torch.testing.assert_close(data["teacher_action"][:, t], label)
        obs, *_ = u.step(C.residual_action(label, data["action"][:, t]))
        torch.testing.assert_close(data["next", "hand"][:, t], obs["extra"]["hand"])
    torch.testing.assert_close(data["action"][:, :, 6:10], torch.full((1, 6, 4), 0.3))
    assert (data["teacher_action"][:, :, 6:] + data["action"][:, :, 6:]).abs().max() > 1.0  # the clip is exercised
    with pytest.raises(ValueError, match="base gait"):
        C.Rollout(R_ID, dict(kw, num_envs=1, sim_backend="physx_cpu"), seed=0, residual=True)


def test_a_rollout_stores_what_stepping_the_env_by_hand_gives():
    """Every stored key of a rollout (observations, rewards, flags, info terms) equals a replay of
    its actions on a fresh ``state_dict`` env of the same seed, across an episode boundary: the
    flat observation's views and the stacking at the end of ``collect`` change nothing."""
    import gymnasium as gym
    from unicross.rl.env import INFO_BOOL, info_float_keys, split_obs
    ro = C.Rollout("UniCross-Grasp-v1", KW, seed=11)
    policy, _ = _models(ro)
    ro.set_actor(policy.module[0].module)
    buf = C.make_buffer(1, 70, ro.dims, ro.n_act)
    ro.collect(buf)
    ro.close()
    env = gym.make("UniCross-Grasp-v1", obs_mode="state_dict", render_backend="none", **KW)
    try:
        obs, _ = env.reset(seed=11)
        for t in range(70):
            for k, x in zip(C.OBS_KEYS, split_obs(obs)):
                assert torch.equal(buf[k][:, t], x), (t, k)
            obs, reward, terminated, truncated, info = env.step(buf["action"][:, t])
            for k, x in zip(C.OBS_KEYS, split_obs(obs)):
                assert torch.equal(buf["next", k][:, t], x), (t, k)
            assert torch.equal(buf["next", "reward"][:, t, 0], reward)
            assert torch.equal(buf["next", "done"][:, t, 0], terminated | truncated)
            for k in info_float_keys() + INFO_BOOL:
                assert torch.equal(buf["next", "info", k][:, t, 0], info[k].to(buf["next", "info", k].dtype)), (t, k)
            if bool((terminated | truncated).any()):
                obs, _ = env.reset()
        assert bool(buf["next", "done"][0, 63, 0])  # the replay crossed an episode boundary
    finally:
        env.close()


def test_alternate_envs_run_whole_episodes_and_change_nothing_at_share_zero():
    """Alternates of a rollout (DAgger's long-horizon chains, ``env.chain_share``): with share 1 every
    episode after the first env's first one runs in the chain, phase by phase (the goal's mode), and
    ends where the chain ends; with share 0 the batch is the one without alternates, bit for bit."""
    from unicross import formulation as F
    first = dict(KW, num_envs=1, sim_backend="physx_cpu",
                 config={"terminate_on_drop": False, "episode_length": {"grasp": 5}})
    chain = ("UniCross-Chain-v1", dict(objects="train-wrappable", object_limit=1, num_envs=1, sim_backend="physx_cpu",
                                       sequence="grasp,relocate,rotate:z+", config={"terminate_on_drop": False},
                                       phase_steps={"grasp": 3, "relocate": 3, "rotate": 3}))
    bufs = {}
    for name, alternates, share in (("chain", [chain], 1.0), ("zero", [chain], 0.0), ("none", None, 0.0)):
        ro = C.Rollout("UniCross-Grasp-v1", first, seed=3, alternates=alternates, alternate_share=share)
        torch.manual_seed(0)
        policy, _ = _models(ro)
        ro.set_actor(policy.module[0].module)
        bufs[name] = C.make_buffer(1, 23, ro.dims, ro.n_act)
        ro.collect(bufs[name])
        ro.close()
    modes = [F.MODES[i] for i in bufs["chain"]["goal"][0, :, :F.NUM_MODES].argmax(-1).tolist()]
    one_chain = ["grasp"] * 3 + ["relocate"] * 3 + ["rotate_z+"] * 3
    assert modes == ["grasp"] * 5 + one_chain + one_chain
    done = bufs["chain"]["next", "done"][0, :, 0].nonzero().flatten().tolist()
    assert done == [4, 13, 22]
    assert all(torch.equal(bufs["zero"][k], bufs["none"][k])
               for k in bufs["none"].keys(include_nested=True, leaves_only=True))
    with pytest.raises(ValueError, match="CPU env workers"):
        LeanCollector("UniCross-Grasp-v1", KW, 2, 4, backend="physx_cuda", alternates=[chain], alternate_share=0.5)


def test_ppo_learner_on_another_device_keeps_the_envs_copy_in_step(tmp_path, monkeypatch):
    """optim.update_device (a learner on the GPU), run here with the learner declared elsewhere: the
    env acts with a copy that takes the learner's weights before each batch, and the checkpoint is
    written on the CPU."""
    import unicross.rl.ppo as P
    monkeypatch.setattr(P, "same_device", lambda a, b: False)
    t = P.PPOTrainer(tmp_path / "run", "grasp", progress=False, overrides=dict(
        env=dict(num_envs=1, object_limit=1, reconfiguration_freq=0),
        collector=dict(total_frames=10 ** 6, horizon=16), optim=dict(minibatch_size=16, mini_epochs=1),
        logging=dict(eval_trials=0, final_eval_trials=0, checkpoint_every=1)))
    try:
        copy = t.collector._shared
        assert copy is not t.algo.actor
        w0 = copy.net.main[-1].weight.clone()
        t.train(max_iterations=2, eval_at_ends=False)
        assert not torch.equal(copy.net.main[-1].weight, w0)  # synced before the second batch
        t.collector.sync_actor()
        assert torch.equal(copy.net.main[-1].weight, t.algo.actor.net.main[-1].weight)
    finally:
        t.close()
    ck = torch.load(tmp_path / "run" / "checkpoint.pt", weights_only=False)
    assert ck["iteration"] == 2 and all(v.device.type == "cpu" for v in ck["policy"].values())


@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device (optim.update_device=cuda)")
def test_ppo_learner_on_the_gpu(tmp_path):
    """optim.update_device=cuda with CPU env workers: the learner on the GPU, the workers' copy on the
    CPU in step with it, a checkpoint on the CPU that a resumed run goes on from."""
    from unicross.rl.ppo import PPOTrainer
    over = dict(env=dict(num_envs=2, object_limit=1, reconfiguration_freq=0), optim=dict(update_device="cuda"),
                collector=dict(total_frames=10 ** 6, frames_per_batch=64), logging=dict(eval_trials=0,
                                                                                      final_eval_trials=0, checkpoint_every=1))
    t = PPOTrainer(tmp_path / "run", "grasp", progress=False, overrides=over)
    try:
        assert next(t.algo.actor.parameters()).is_cuda and not next(t.collector._shared.parameters()).is_cuda
        t.train(max_iterations=2, eval_at_ends=False)
        t.collector.sync_actor()
        assert torch.equal(t.collector._shared.net.main[-1].weight, t.algo.actor.net.main[-1].weight.cpu())
    finally:
        t.close()
    ck = torch.load(tmp_path / "run" / "checkpoint.pt", weights_only=False, map_location="cpu")
    assert all(v.device.type == "cpu" for v in ck["policy"].values())
    r = PPOTrainer(tmp_path / "run", resume=True, progress=False)
    try:
        r.train(max_iterations=1, eval_at_ends=False)
        assert r.iteration == 3
    finally:
        r.close()
