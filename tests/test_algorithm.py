"""The PPO algorithm on synthetic batches: no simulator, seconds."""
import pytest
import torch

from unicross.config import load_config
from unicross.rl.algorithm import PPO
from unicross.rl.collector import make_buffer
from unicross.rl.models import OBS_KEYS

pytestmark = pytest.mark.unit

DIMS = dict(hand=6, object=5, goal=4)
N, T, A = 4, 64, 3


def bandit_batch(algo: PPO, g: torch.Generator):
    """One batch of a one-step bandit: reward = the first action component; every step ends an
    episode. Actions are sampled from the algorithm's current policy, as the collector does."""
    buf = make_buffer(N, T, DIMS, A)
    for k in OBS_KEYS:
        buf[k] = torch.randn(N, T, DIMS[k], generator=g)
        buf["next", k] = torch.randn(N, T, DIMS[k], generator=g)
    with torch.no_grad():
        loc, scale = algo.actor(*(buf[k] for k in OBS_KEYS))
        noise = torch.randn(loc.shape, generator=g)
        buf["loc"], buf["scale"], buf["action"] = loc, scale, loc + scale * noise
        buf["action_log_prob"] = algo.policy.get_dist(buf.select(*OBS_KEYS)).log_prob(buf["action"])
    buf["next", "reward"] = buf["action"][..., :1].clamp(-1, 1)
    buf["next", "done"][:] = True
    buf["next", "terminated"][:] = True
    return buf


def make_algo(**optim):
    cfg = load_config("ppo", {"optim": optim})
    torch.manual_seed(0)
    return PPO(DIMS, A, cfg, frames_per_batch=N * T)


def mean_first_action(algo: PPO) -> float:
    with torch.no_grad():
        obs = [torch.zeros(256, DIMS[k]) for k in OBS_KEYS]
        return float(algo.actor(*obs)[0][:, 0].mean())


def test_ppo_update_learns_a_bandit():
    algo = make_algo()
    g = torch.Generator().manual_seed(1)
    start = mean_first_action(algo)
    for _ in range(15):
        out = algo.update(bandit_batch(algo, g))
    for k in ("loss_objective", "loss_critic", "kl", "lr", "clip_fraction", "minibatch_steps", "value_mean"):
        assert k in out
    assert out["minibatch_steps"] == 5  # mini_epochs x (256 frames / minibatch 256)
    assert mean_first_action(algo) > start + 0.3  # the rewarded action component grew
    assert algo.norm.count > N * T  # observation statistics follow the batches


def test_kl_stop_and_state_round_trip():
    algo = make_algo(kl_stop=0.0)  # any positive KL ends the epochs
    g = torch.Generator().manual_seed(2)
    for _ in range(2):  # 5 minibatch steps without kl_stop (above); the first positive KL ends them
        assert algo.update(bandit_batch(algo, g))["minibatch_steps"] < 5
    other = make_algo()
    other.load_state_dict(algo.state_dict())
    obs = [torch.randn(8, DIMS[k], generator=g) for k in OBS_KEYS]
    assert torch.equal(other.actor(*obs)[0], algo.actor(*obs)[0])
    assert other.lr == algo.lr


def test_adaptive_rate_ignores_the_kl_of_the_updates_first_step():
    """The first minibatch step of an update measures the policy that collected the batch (KL 0):
    it must not move the rate. With every KL below half the threshold, each later step raises
    it x1.5: 4 raises in 5 steps (before the fix 5; with kl_stop that pinned the rate at lr_max,
    x1.5 at the first step and /1.5 at the stop)."""
    algo = make_algo(lr=1.0e-5, kl_threshold=10.0, lr_max=1.0)
    out = algo.update(bandit_batch(algo, torch.Generator().manual_seed(3)))
    assert out["minibatch_steps"] == 5
    assert out["lr"] == pytest.approx(1.0e-5 * 1.5 ** 4)


def test_critic_warmup_leaves_the_actor_alone_then_hands_over():
    """``optim.critic_warmup``: the first N updates move the critic only (the actor's weights and
    the rate stay); the update after them moves the actor too; the count survives a state round trip."""
    algo = make_algo(critic_warmup=2)
    g = torch.Generator().manual_seed(4)
    actor0 = [p.detach().clone() for p in algo.actor.parameters()]
    critic0 = [p.detach().clone() for p in algo.value.critic.parameters()]
    for _ in range(2):
        out = algo.update(bandit_batch(algo, g))
        assert out["critic_only"] == 1.0 and out["lr"] == algo.cfg["optim"]["lr"]
    assert all(torch.equal(a, b) for a, b in zip(actor0, algo.actor.parameters()))
    assert not all(torch.equal(a, b) for a, b in zip(critic0, algo.value.critic.parameters()))
    other = make_algo(critic_warmup=2)
    other.load_state_dict(algo.state_dict())
    assert other.updates == 2
    assert algo.update(bandit_batch(algo, g))["critic_only"] == 0.0
    assert not all(torch.equal(a, b) for a, b in zip(actor0, algo.actor.parameters()))


def test_teacher_term_pulls_the_mean_to_the_teacher_and_decays():
    """``loss.teacher_coef``: with no reward to follow, the actor's mean moves to the teacher's
    action on the batch's states; without the term it stays near 0; the weight decays by
    ``loss.teacher_decay`` per actor update (counted after the critic warm-up)."""
    target = torch.tensor([0.6, -0.4, 0.2])

    def run(coef):
        cfg = load_config("ppo", {"loss": {"teacher_coef": coef, "teacher_decay": 0.8}, "optim": {"critic_warmup": 1}})
        torch.manual_seed(0)
        algo = PPO(DIMS, A, cfg, frames_per_batch=N * T)
        g = torch.Generator().manual_seed(5)
        coefs = []
        for _ in range(12):
            buf = bandit_batch(algo, g)
            buf["next", "reward"].zero_()
            buf["teacher_action"] = target.expand(N, T, A).clone()
            out = algo.update(buf)
            coefs.append(out["teacher_coef"])
        with torch.no_grad():
            obs = [torch.randn(256, DIMS[k], generator=g) for k in OBS_KEYS]
            return algo.actor(*obs)[0].mean(0), coefs, out

    mean, coefs, out = run(20.0)
    assert coefs[:4] == pytest.approx([0.0, 20.0, 16.0, 12.8])
    assert out["loss_teacher"] > 0
    torch.testing.assert_close(mean, target, atol=0.15, rtol=0)
    mean0, _, out0 = run(0.0)
    assert out0["loss_teacher"] == 0.0
    assert (mean0 - target).abs().max() > 0.15


@pytest.mark.parametrize("mode, init_policy, frozen", [(None, None, False), (None, "allegro/rotate_y-", True),
                                                      ("running", "allegro/rotate_y-", False), ("frozen", None, True)])
def test_observation_statistics_freeze_with_a_copied_policy(mode, init_policy, frozen):
    """``model.obs_stats``: running statistics fold every batch in; frozen ones stay as the first batch
    (or ``model.init_policy``) left them, so a copied policy keeps its input scaling; null freezes them
    exactly when the run starts from a policy. A bad value is refused."""
    cfg = load_config("ppo", {"model": {"obs_stats": mode, "init_policy": init_policy}})
    torch.manual_seed(0)
    algo = PPO(DIMS, A, cfg, frames_per_batch=N * T)
    g = torch.Generator().manual_seed(1)
    algo.update(bandit_batch(algo, g))  # the first batch fits the statistics either way
    after_first = {k: v.clone() for k, v in algo.norm.state_dict().items()}
    algo.update(bandit_batch(algo, g))
    same = all(torch.equal(after_first[k], v) for k, v in algo.norm.state_dict().items())
    assert same == frozen
    with pytest.raises(ValueError, match="model.obs_stats"):
        PPO(DIMS, A, load_config("ppo", {"model": {"obs_stats": "fixed"}}), frames_per_batch=N * T)


@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device (optim.update_device=cuda)")
def test_update_on_the_gpu_matches_the_cpu():
    """optim.update_device=cuda: the same batch, the same minibatch order (the sampler draws on the
    CPU's generator) and the same starting weights give the CPU's update to float rounding."""
    cpu = make_algo()
    gpu = PPO(DIMS, A, load_config("ppo"), frames_per_batch=N * T, device="cuda")
    gpu.policy.load_state_dict(cpu.policy.state_dict())
    gpu.value.load_state_dict(cpu.value.state_dict())
    g = torch.Generator().manual_seed(1)
    for _ in range(3):
        batch = bandit_batch(cpu, g)
        torch.manual_seed(7)
        out_c = cpu.update(batch.clone())
        torch.manual_seed(7)
        out_g = gpu.update(batch.clone().to("cuda"))
        for k in ("loss_objective", "loss_critic", "kl", "value_mean"):
            assert out_g[k] == pytest.approx(out_c[k], rel=1e-3, abs=1e-5), k
    obs = [torch.randn(64, DIMS[k], generator=g) for k in OBS_KEYS]
    with torch.no_grad():
        loc_c, _ = cpu.actor(*obs)
        loc_g, _ = gpu.actor(*(o.cuda() for o in obs))
    assert torch.allclose(loc_g.cpu(), loc_c, atol=1e-3)
    assert torch.allclose(gpu.norm.hand_mean.cpu(), cpu.norm.hand_mean, atol=1e-5)
