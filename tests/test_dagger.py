"""DAgger: the trainer refuses to start without every expert; a real tiny run lowers the
student's action MSE to the experts on held-out states of every mode."""
import copy
import shutil

import pytest
import torch

from unicross import formulation as F
from unicross.rl.dagger import DAggerTrainer, distill_loss, expert_paths, mode_weight_vector
from unicross.rl.env import ManiSkillEnv
from unicross.rl.ppo import PPOTrainer

SHORT = dict(grasp=8, relocate=8, rotate=8, translate=8)


@pytest.fixture(scope="module")
def experts(tmp_path_factory):
    """Ten tiny PPO experts (one short iteration each), written as `unicross train` writes them
    (in-hand skills start from the shipped grasp dataset)."""
    root = tmp_path_factory.mktemp("experts")
    for mode in F.MODES:
        skill = F.mode_skill(mode)
        axis = mode.split("_")[1] if "_" in mode else None
        t = PPOTrainer(root / mode, skill, axis, overrides=dict(
            env=dict(num_envs=1, object_limit=1, reconfiguration_freq=0),
            collector=dict(total_frames=16, horizon=16), optim=dict(minibatch_size=16, mini_epochs=1),
            logging=dict(eval_trials=0, final_eval_trials=0)), progress=False)
        t.train(eval_at_ends=False)
        t.close()
    return root


def _tiny_cfg(num_envs=1, grad_steps=2, epochs=2, **collector):
    """Overrides of a few-step DAgger run on one object (``collector``: more collector fields)."""
    return dict(env=dict(num_envs=num_envs, object_limit=1, reconfiguration_freq=0, randomize=False,
                         task_config=dict(episode_length=SHORT)),
                collector=dict(rollout_steps=4, **collector), optim=dict(batch_size=8, grad_steps=grad_steps, epochs=epochs),
                buffer=dict(capacity=100), logging=dict(checkpoint_every=1))


def _held_out(seed=99):
    """States of every mode from separate rollouts with random actions."""
    tds = []
    for mode in F.MODES:
        env = ManiSkillEnv("UniCross-MultiSkill-v1", dict(object_limit=1, modes=[mode], randomize=False))
        env.set_seed(seed)
        tds.append(env.rollout(6).select("hand", "object", "goal"))
        env.close()
    return torch.cat(tds)


def test_refuses_to_start_without_every_expert(tmp_path, experts):
    with pytest.raises(FileNotFoundError, match="rotate_x"):
        expert_paths(tmp_path)
    with pytest.raises(ValueError, match="--experts"):
        DAggerTrainer(tmp_path / "run", None)
    # every mode's folder needs that mode's expert: a grasp expert copied into rotate_x+ is refused
    fake = tmp_path / "fake"
    for m in F.MODES:
        (fake / m).mkdir(parents=True)
        src = experts / ("grasp" if m == "rotate_x+" else m) / "checkpoint.pt"
        (fake / m / "checkpoint.pt").symlink_to(src)
    with pytest.raises(ValueError, match="trained for mode 'grasp', not 'rotate_x\\+'"):
        DAggerTrainer(tmp_path / "run2", fake, progress=False)
    # another grasp-state dataset for the in-hand modes' starts must exist (refused before any worker starts)
    with pytest.raises(FileNotFoundError, match="env.grasp_dataset"):
        DAggerTrainer(tmp_path / "run3", experts, overrides=dict(env=dict(grasp_dataset=str(tmp_path / "none.pt"))),
                      progress=False)
    # a chain count for a mode that has no chain (env.chain_repeats) is refused before any worker starts
    with pytest.raises(ValueError, match="env.chain_repeats"):
        DAggerTrainer(tmp_path / "run4", experts, overrides=dict(env=dict(chain_share=0.2, chain_repeats={"grasp": 2})),
                      progress=False)


def test_tiny_dagger_lowers_action_mse_on_every_mode(tmp_path, experts):
    cfg = dict(env=dict(num_envs=1, object_limit=1, reconfiguration_freq=1, randomize=False,
                        task_config=dict(episode_length=SHORT)),
               collector=dict(rollout_steps=8), optim=dict(batch_size=64, grad_steps=20, epochs=26, lr=1e-3),
               buffer=dict(capacity=5000), logging=dict(checkpoint_every=100))
    t = DAggerTrainer(tmp_path / "run", experts, overrides=cfg, progress=False)
    held = _held_out()
    before = t.action_mse(held)
    t.train()
    after = t.action_mse(held)
    assert set(before) == set(F.MODES)
    seen = set(t.rb[:]["mode"].tolist())
    assert seen == set(range(F.NUM_MODES))  # the buffer holds states of every mode
    for m in F.MODES:
        assert after[m] < before[m], (m, before[m], after[m])
    sample = t.rb.sample(8)
    assert set(sample.keys()) >= {"hand", "object", "goal", "expert_action", "mode"}
    assert sample["expert_action"].shape == (8, 22)
    # teachers are frozen and in eval mode
    assert all(not p.requires_grad for p in t.teachers.parameters())
    t.close()


def test_dagger_resume(tmp_path, experts, capsys):
    cfg = _tiny_cfg()
    t = DAggerTrainer(tmp_path / "run", experts, overrides=cfg, progress=False)
    t.train()
    opt = t.optim.state_dict()
    n = len(t.rb)
    t.close()
    # the replay buffer sits in a directory the checkpoint names (written before it, atomically swapped)
    ck = torch.load(tmp_path / "run" / "checkpoint.pt", weights_only=False)
    assert ck["replay_dir"] == "replay-000002" and [p.name for p in (tmp_path / "run").glob("replay*")] == ["replay-000002"]
    with pytest.raises(ValueError, match="unicross distill --resume"):
        PPOTrainer(tmp_path / "run", resume=True, progress=False)
    r = DAggerTrainer(tmp_path / "run", resume=True, progress=False, overrides=dict(optim=dict(lr=1.0e-4)))
    assert r.epoch == 2 and len(r.rb) == n
    for k, s in opt["state"].items():
        assert torch.equal(s["exp_avg"], r.optim.state_dict()["state"][k]["exp_avg"])
    # a learning rate given on resume is the one the optimiser steps with (its saved state holds the old one)
    assert all(g["lr"] == 1.0e-4 for g in r.optim.param_groups)
    assert "resumed with optim.lr=0.0001 (was 0.0003)" in capsys.readouterr().out
    r.train(epochs=1)
    assert r.epoch == 3
    r.close()


def test_a_resume_with_a_changed_teacher_labels_its_rows_again(tmp_path, experts, capsys):
    """Resumed with another experts folder where only rotate_z+'s teacher differs, the replay buffer's rotate_z+
    rows carry the new teacher's labels and every other row keeps its own; the same teachers relabel nothing."""
    cfg = _tiny_cfg(num_envs=1, epochs=10)  # 40 steps: five episodes of 8 steps, both modes among them
    cfg["env"].update(modes=["grasp", "rotate_z+"], reconfiguration_freq=1)  # a new (object, mode) pair each episode
    t = DAggerTrainer(tmp_path / "run", experts, overrides=cfg, progress=False)
    t.train()
    before = t.rb[:].clone()
    t.close()
    zp = F.MODES.index("rotate_z+")
    assert {0, zp} <= set(before["mode"].tolist())  # both modes' rows are stored
    other = tmp_path / "experts2"
    for m in ("grasp", "rotate_z+"):
        (other / m).mkdir(parents=True)
    shutil.copy(experts / "grasp" / "checkpoint.pt", other / "grasp" / "checkpoint.pt")  # the same file
    ck = torch.load(experts / "rotate_z+" / "checkpoint.pt", weights_only=False)
    g = torch.Generator().manual_seed(0)  # another z+ teacher: the same network with other weights
    ck["policy"] = {k: v + 0.5 * torch.randn(v.shape, generator=g) if v.is_floating_point() and "weight" in k else v
                    for k, v in ck["policy"].items()}
    torch.save(ck, other / "rotate_z+" / "checkpoint.pt")
    capsys.readouterr()
    r = DAggerTrainer(tmp_path / "run", other, resume=True, progress=False)
    assert "other teachers for rotate_z+:" in capsys.readouterr().out
    after = r.rb[:]
    z = before["mode"] == zp
    assert torch.equal(after["expert_action"][~z], before["expert_action"][~z])
    assert not torch.allclose(after["expert_action"][z], before["expert_action"][z])
    assert torch.allclose(after["expert_action"][z], r.teachers(before[z].select("hand", "object", "goal")))
    assert r.state()["expert_digests"]["rotate_z+"] != r.state()["expert_digests"]["grasp"]
    r.train(epochs=1)
    r.close()
    # resumed again with the same teachers: no row is labelled again
    r = DAggerTrainer(tmp_path / "run", other, resume=True, progress=False)
    assert "other teachers" not in capsys.readouterr().out
    r.close()


def test_dagger_with_overlapped_rollouts_fills_and_resumes(tmp_path, experts):
    """collector.overlap: two workers roll out the next epoch during the update; every epoch adds
    its rollout to the buffer, the last starts none, and a resumed run goes on."""
    cfg = _tiny_cfg(num_envs=2, overlap=True)
    t = DAggerTrainer(tmp_path / "run", experts, overrides=cfg, progress=False)
    try:
        t.train()
        assert t.epoch == 2 and len(t.rb) == 16 and t.frames == 16 and not t.collector.pending
    finally:
        t.close()
    r = DAggerTrainer(tmp_path / "run", resume=True, progress=False)
    try:
        r.train(epochs=1)
        assert r.epoch == 3 and len(r.rb) == 24
    finally:
        r.close()
    with pytest.raises(ValueError, match="collector.overlap needs env worker processes"):
        DAggerTrainer(tmp_path / "one", experts, overrides=dict(cfg, env=dict(cfg["env"], num_envs=1)), progress=False)


@pytest.mark.slow
def test_dagger_on_ray_env_actors_fills_the_buffer_local_workers_fill(tmp_path, experts):
    """DAgger with collector.ray_address (a loopback Ray cluster) labels the same states as with
    local worker processes: one epoch gives the same replay buffer, bit for bit."""
    ray = pytest.importorskip("ray")
    cfg = _tiny_cfg(num_envs=2, grad_steps=1, epochs=1)
    local = DAggerTrainer(tmp_path / "local", experts, overrides=cfg, progress=False)
    local.train()
    local.close()
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        on_ray = DAggerTrainer(tmp_path / "ray", experts, overrides=dict(cfg, collector=dict(rollout_steps=4, ray_address="local")),
                               progress=False)
        on_ray.train()
        on_ray.close()
    finally:
        ray.shutdown()
    a, b = local.rb[:], on_ray.rb[:]
    for k in ("hand", "object", "goal", "expert_action", "mode"):
        assert torch.equal(a[k], b[k]), k


def test_dagger_starts_from_a_student_and_learns_around_its_states(tmp_path, experts):
    """model.init_policy starts the student from another student's weights and statistics (a
    policy of another skill is refused before any worker starts); optim.label_noise perturbs the
    hand and object observations of a share of each batch, leaves the goal (the teacher's key) as
    it is, and the update reports the error on those rows apart; optim.warmup_frames holds the updates
    back until the buffer is that full."""
    cfg = _tiny_cfg()
    first = DAggerTrainer(tmp_path / "first", experts, overrides=cfg, progress=False)
    first.train()
    first.close()
    with pytest.raises(ValueError, match="label_noise_modes: unknown mode"):
        DAggerTrainer(tmp_path / "typo", experts, progress=False,
                      overrides=dict(cfg, optim=dict(cfg["optim"], label_noise_modes=["translate_z"])))
    with pytest.raises(ValueError, match="acts for skill/axis/hand"):
        DAggerTrainer(tmp_path / "wrong", experts, progress=False,
                      overrides=dict(cfg, model=dict(init_policy=str(experts / "grasp" / "checkpoint.pt"))))
    noisy = dict(cfg, optim=dict(cfg["optim"], label_noise=0.5, label_noise_share=0.5, label_noise_modes=["grasp"]),
                 model=dict(init_policy=str(tmp_path / "first" / "checkpoint.pt")))
    t = DAggerTrainer(tmp_path / "second", experts, overrides=noisy, progress=False)
    try:
        theirs = first.student.state_dict()
        assert all(torch.equal(v, theirs[k]) for k, v in t.student.state_dict().items())
        t.collect()
        b = t.rb.sample()
        b["mode"][:] = torch.tensor([0, 1, 0, 1, 0, 1, 0, 1])  # grasp, relocate, ...
        obs = b.select("hand", "object", "goal").clone()
        moved = t._perturb(obs, b["mode"], 0.5, 0.5)
        assert moved.tolist() == [True, False, True, False] + [False] * 4  # the first half's grasp rows
        for key in ("hand", "object"):
            assert (obs[key] != b[key]).any(-1).tolist() == moved.tolist()
        assert torch.equal(obs["goal"], b["goal"])
        t.cfg["optim"]["label_noise_modes"] = None  # every mode (this run's buffer holds one other mode)
        upd = t.update()
        assert {"loss", "mse", "mse_perturbed"} <= set(upd) and upd["mse_perturbed"] > 0
        # optim.warmup_frames: epochs only collect (and log no loss) until the buffer holds that many rows
        before = {k: v.detach().clone() for k, v in t.actor.named_parameters()}  # statistics keep running
        n = len(t.rb)
        t.cfg["optim"]["warmup_frames"] = n + 2 * cfg["collector"]["rollout_steps"]
        assert "loss" not in t.train(epochs=1) and len(t.rb) > n
        assert all(torch.equal(v, before[k]) for k, v in t.actor.named_parameters())
        assert "loss" in t.train(epochs=1)
        assert not all(torch.equal(v, before[k]) for k, v in t.actor.named_parameters())
    finally:
        t.close()


def test_mode_weights_weigh_each_rows_error_by_its_mode():
    """optim.mode_weights: the weight vector follows F.MODES (1 where unnamed, all ones with no weights); typos and
    weights that are not positive finite numbers are refused."""
    w = mode_weight_vector({"rotate_x+": 10, "grasp": 0.5})
    assert w[F.MODES.index("rotate_x+")] == 10 and w[F.MODES.index("grasp")] == 0.5
    assert int((w == 1).sum()) == F.NUM_MODES - 2
    assert torch.equal(mode_weight_vector({}), torch.ones(F.NUM_MODES))
    with pytest.raises(ValueError, match="unknown mode"):
        mode_weight_vector({"rotate_x": 2})
    for bad in (0, -1, float("inf"), True, "2"):
        with pytest.raises(ValueError, match="positive finite"):
            mode_weight_vector({"grasp": bad})


def test_distill_loss_l1_keeps_a_gradient_at_small_errors():
    """optim.l1 = 0 is the weighted MSE; with l1 > 0 the gradient at an error of 1e-3 is l1 / n_act per unit weight
    (the squared error's alone: 2e-3 / n_act); negative or infinite l1 is refused."""
    pred = torch.full((4, 2), 1e-3, requires_grad=True)
    target = torch.zeros(4, 2)
    w = torch.tensor([1.0, 1.0, 3.0, 1.0])
    loss, err = distill_loss(pred, target, w)
    assert torch.allclose(loss, (w * ((pred - target) ** 2).mean(-1)).sum() / w.sum())
    assert torch.allclose(err, torch.full((4,), 1e-6))
    (g_mse,) = torch.autograd.grad(loss, pred)
    loss_l1, _ = distill_loss(pred, target, w, l1=0.01)
    (g_l1,) = torch.autograd.grad(loss_l1, pred)
    assert torch.allclose(g_l1 - g_mse, 0.01 / 2 * (w / w.sum())[:, None].expand(4, 2))
    assert bool((g_l1 > 5 * g_mse).all())  # 6x here: 1e-3 + 5e-3 against 1e-3, per unit weight
    for bad in (-0.1, float("inf")):
        with pytest.raises(ValueError, match="optim.l1"):
            distill_loss(pred, target, w, l1=bad)


def test_weighted_update_moves_the_student_toward_the_weighted_mode(tmp_path, experts):
    """One update on a batch of two modes with the same rows: weighting one mode 100x makes the step lower that
    mode's error more than the unweighted step does."""
    cfg = _tiny_cfg(grad_steps=1)
    t = DAggerTrainer(tmp_path / "run", experts, overrides=cfg, progress=False)
    try:
        t.collect()
        b = t.rb[: len(t.rb)]
        start = {k: v.detach().clone() for k, v in t.actor.state_dict().items()}
        opt = copy.deepcopy(t.optim.state_dict())
        errs = {}
        for weights in ({}, {"rotate_x+": 100.0}):
            t.actor.load_state_dict(start)
            t.optim.load_state_dict(opt)
            t.mode_weights = mode_weight_vector(weights)
            half = b.batch_size[0] // 2
            batch = b.clone()
            batch["mode"][:half] = F.MODES.index("rotate_x+")
            batch["mode"][half:] = F.MODES.index("grasp")
            batch["expert_action"][:half] = 1.0  # the x+ rows ask for far-away actions
            t.rb.sample = lambda batch=batch: batch
            t.update()
            with torch.no_grad():
                pred = t.actor(batch.select("hand", "object", "goal"))["loc"][:half]
            errs[bool(weights)] = float(((pred - 1.0) ** 2).mean())
        assert errs[True] < errs[False]
    finally:
        t.close()


def test_chain_share_adds_one_chain_per_in_hand_mode_on_the_multi_skill_objects():
    """``env.chain_share``: the chains the student also acts in (grasp, relocate, one in-hand mode each),
    with the multi-skill env's settings and objects (default the training set); refused without
    grasp and relocate, or outside [0, 1]; none at 0 (the paper's DAgger)."""
    from unicross import formulation as F
    from unicross.rl.dagger import chain_envs
    kw = dict(randomize=True, modes=list(F.MODES), reconfiguration_freq=2, config=None, hand="allegro",
              grasp_dataset="x.pt")
    assert chain_envs(kw, 0.0) == []
    got = chain_envs(kw, 0.3)
    assert [k["sequence"][-1] for _, k in got] == [m for m in F.MODES if m.startswith(("rotate", "translate"))]
    for env_id, k in got:
        assert env_id == "UniCross-Chain-v1" and k["sequence"][:2] == ["grasp", "relocate"]
        assert k["objects"] == "train" and "grasp_dataset" not in k and "modes" not in k and k["hand"] == "allegro"
    assert chain_envs(dict(kw, objects="test"), 1.0)[0][1]["objects"] == "test"
    with pytest.raises(ValueError, match="grasp, relocate"):
        chain_envs(dict(kw, modes=["grasp", "rotate_x+"]), 0.5)
    with pytest.raises(ValueError, match="chain_share"):
        chain_envs(kw, 1.5)


def test_mode_repeats_walk_a_mode_and_its_chains_k_times():
    """env.mode_repeats={m: k}: the multi-skill env's pair walk takes k pairs of m per round (the others
    one), chains of m come k times; unknown modes and repeats under 1 are refused before any env."""
    from tasks.base import pair_walk
    from unicross import formulation as F
    from unicross.rl.dagger import chain_envs, walked_modes
    assert walked_modes(F.MODES, {}) == list(F.MODES) == walked_modes(F.MODES, None)
    modes = walked_modes(F.MODES, {"rotate_y+": 2})
    assert len(modes) == 11 and modes.count("rotate_y+") == 2 and set(modes) == set(F.MODES)
    walk = pair_walk([[0, 1, 2]] * len(modes), [F.MODES.index(m) for m in modes], "sequential")
    yplus = F.MODES.index("rotate_y+")
    assert sum(m == yplus for _, m in walk) == 6 and sum(m == 0 for _, m in walk) == 3
    kw = dict(randomize=True, modes=modes, reconfiguration_freq=2, config=None, hand="allegro")
    assert [k["sequence"][-1] for _, k in chain_envs(kw, 0.2)].count("rotate_y+") == 2
    with pytest.raises(ValueError, match="not among"):
        walked_modes(["grasp", "relocate"], {"rotate_y+": 2})
    # env.chain_repeats sets a chain's count over the walk's: the same list by default, k copies, 0 drops it
    assert chain_envs(kw, 0.2, {}) == chain_envs(kw, 0.2)
    tails = [k["sequence"][-1] for _, k in chain_envs(kw, 0.2, {"translate_z-": 3, "rotate_y+": 0, "rotate_x+": 1})]
    assert tails.count("translate_z-") == 3 and "rotate_y+" not in tails and tails.count("rotate_x+") == 1
    assert tails.count("rotate_z+") == 1 and len(tails) == 9
    for bad, match in (({"grasp": 2}, "not among"), ({"translate_z-": -1}, "whole numbers"),
                       ({"translate_z-": 1.5}, "whole numbers"),
                       ({m: 0 for m in F.MODES if m.startswith(("rotate", "translate"))}, "leaves no chain")):
        with pytest.raises(ValueError, match=match):
            chain_envs(kw, 0.2, bad)
    for bad in (0, 1.5, True):
        with pytest.raises(ValueError, match="whole numbers"):
            walked_modes(F.MODES, {"rotate_y+": bad})


def test_learner_on_another_device_keeps_the_workers_copy_in_step(tmp_path, experts, monkeypatch):
    """optim.update_device (a learner on the GPU), run here with the learner declared elsewhere: the
    envs act with a copy that takes the student's weights before each rollout, the checkpoint is
    written on the CPU and a resumed run goes on from it."""
    import unicross.rl.dagger as D
    monkeypatch.setattr(D, "same_device", lambda a, b: False)
    t = DAggerTrainer(tmp_path / "run", experts, overrides=_tiny_cfg(epochs=3, grad_steps=3), progress=False)
    copy = t.collector._shared
    assert copy is not t.actor.module
    w0 = copy.net.main[-1].weight.clone()
    t.train()
    assert not torch.equal(copy.net.main[-1].weight, w0)  # synced before the later rollouts
    t.collector.sync_actor()
    assert torch.equal(copy.net.main[-1].weight, t.actor.module.net.main[-1].weight)
    t.close()
    ck = torch.load(tmp_path / "run" / "checkpoint.pt", weights_only=False)
    assert ck["epoch"] == 3 and all(v.device.type == "cpu" for v in ck["policy"].values())
    r = DAggerTrainer(tmp_path / "run", None, resume=True, progress=False)
    r.train(epochs=1)
    assert r.epoch == 4
    r.close()


@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device (optim.update_device=cuda)")
def test_dagger_learner_on_the_gpu(tmp_path, experts):
    """optim.update_device=cuda: teachers and student on the GPU, the replay buffer and the workers'
    copy on the CPU, the checkpoint on the CPU."""
    over = _tiny_cfg(num_envs=2, epochs=3, grad_steps=3)
    over["optim"]["update_device"] = "cuda"
    t = DAggerTrainer(tmp_path / "run", experts, overrides=over, progress=False)
    assert next(t.actor.parameters()).is_cuda and not next(t.collector._shared.parameters()).is_cuda
    t.train()
    t.collector.sync_actor()
    assert torch.equal(t.collector._shared.net.main[-1].weight, t.actor.module.net.main[-1].weight.cpu())
    assert t.rb[:]["expert_action"].device.type == "cpu"
    t.close()
    ck = torch.load(tmp_path / "run" / "checkpoint.pt", weights_only=False, map_location="cpu")
    assert all(v.device.type == "cpu" for v in ck["policy"].values())
