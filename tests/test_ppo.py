"""TorchRL side: env specs, a tiny PPO run that learns weights, resume after interruption."""
import gzip
import signal
import subprocess
import sys
import time

import pytest
import torch
from torchrl.envs.utils import check_env_specs

from unicross.rl.env import ManiSkillEnv
from unicross.rl.ppo import PPOTrainer

TINY = dict(env=dict(num_envs=1, object_limit=1), collector=dict(total_frames=96, horizon=16),
            optim=dict(minibatch_size=8, mini_epochs=2), logging=dict(eval_trials=0, final_eval_trials=0, checkpoint_every=1))


@pytest.mark.parametrize("env_id,kw", [("UniCross-Grasp-v1", {}), ("UniCross-Relocate-v1", {}),
                                       ("UniCross-Rotate-v1", {"axis": "y-"}),
                                       ("UniCross-Translate-v1", {"direction": "z+"}), ("UniCross-MultiSkill-v1", {})])
def test_check_env_specs(env_id, kw, grasp_file):
    args = dict(object_limit=1, **kw)
    if env_id != "UniCross-Grasp-v1":
        args["grasp_dataset"] = grasp_file
    env = ManiSkillEnv(env_id, args)
    check_env_specs(env)
    td = env.rollout(3)
    assert td["hand"].shape == (3, 44) and td["object"].shape == (3, 105) and td["goal"].shape == (3, 55)
    assert td["next", "terminated"].dtype == torch.bool and td["next", "truncated"].dtype == torch.bool
    env.close()


def test_tiny_ppo_updates_weights_with_finite_losses(tmp_path):
    t = PPOTrainer(tmp_path / "run", "grasp", overrides=TINY, progress=False)
    before = [p.detach().clone() for p in list(t.policy.parameters()) + list(t.value.parameters())]
    t.train(max_iterations=2)
    after = list(t.policy.parameters()) + list(t.value.parameters())
    assert any(not torch.equal(a, b) for a, b in zip(before, after))
    assert t.norm.count > 1  # observation statistics were updated
    rows = (tmp_path / "run" / "metrics.csv").read_text().strip().splitlines()
    assert len(rows) == 3
    header = rows[0].split(",")
    for row in rows[1:]:
        vals = dict(zip(header, row.split(",")))
        for k in ("loss_objective", "loss_critic", "kl", "reward_contact", "reward_track"):
            assert vals[k] != "" and torch.isfinite(torch.tensor(float(vals[k])))
    t.close()


def test_overlapped_collection_trains_and_resumes(tmp_path):
    """collector.overlap: two env workers collect each batch during the previous update; the run
    counts the frames it trains on, checkpoints and resumes; one env is refused before simulating."""
    over = dict(TINY, env=dict(num_envs=2, object_limit=1), collector=dict(total_frames=96, horizon=16, overlap=True))
    t = PPOTrainer(tmp_path / "run", "grasp", overrides=over, progress=False)
    try:
        before = [p.detach().clone() for p in t.policy.parameters()]
        t.train(max_iterations=2)
        assert t.frames == 64 and t.collector.pending  # the third batch is on its way
        assert any(not torch.equal(a, b) for a, b in zip(before, t.policy.parameters()))
        t.save()
    finally:
        t.close()
    t = PPOTrainer(tmp_path / "run", resume=True, progress=False)
    try:
        t.train()
        assert t.frames == 96 and t.iteration == 3 and not t.collector.pending
    finally:
        t.close()
    with pytest.raises(ValueError, match="collector.overlap needs env worker processes"):
        PPOTrainer(tmp_path / "one", "grasp", overrides=dict(TINY, collector=dict(total_frames=96, horizon=16,
                                                                                   overlap=True)), progress=False)


def test_training_needs_no_edit_for_another_hand(tmp_path):
    """The same trainer, networks and checkpoint for the 28-DoF Sharpa Wave (in-hand rotate,
    starting from its shipped grasps): sizes follow from the hand description."""
    from unicross.robots.hand import load_hand
    spec = load_hand("sharpa_wave")
    t = PPOTrainer(tmp_path / "run", "rotate", axis="z+", hand="sharpa_wave", overrides=TINY, progress=False)
    assert t.n_act == spec.dof == 28
    before = [p.detach().clone() for p in t.policy.parameters()]
    t.train(max_iterations=1)
    assert any(not torch.equal(a, b) for a, b in zip(before, t.policy.parameters()))
    t.close()
    ck = torch.load(tmp_path / "run" / "checkpoint.pt", weights_only=False)
    assert ck["hand"] == "sharpa_wave"


def test_resume_continues_with_identical_optimiser_state(tmp_path):
    run = tmp_path / "run"
    t = PPOTrainer(run, "grasp", overrides=TINY, progress=False)
    t.train(max_iterations=2)
    opt_state = t.optim.state_dict()
    weights = {k: v.clone() for k, v in t.policy.state_dict().items()}
    t.close()
    with pytest.raises(FileExistsError):
        PPOTrainer(run, "grasp", overrides=TINY, progress=False)
    r = PPOTrainer(run, resume=True, progress=False)
    assert r.iteration == 2 and r.frames == 32
    ro = r.optim.state_dict()
    assert ro["param_groups"][0]["lr"] == opt_state["param_groups"][0]["lr"]
    for k, s in opt_state["state"].items():
        for name, v in s.items():
            assert torch.equal(torch.as_tensor(v), torch.as_tensor(ro["state"][k][name]))
    for k, v in r.policy.state_dict().items():
        assert torch.equal(v, weights[k])
    r.train(max_iterations=1)
    assert r.iteration == 3
    lines = (run / "metrics.csv").read_text().strip().splitlines()
    assert [l.split(",")[0] for l in lines[1:]] == ["1", "2", "3"]
    r.close()


def test_resume_after_kill_9(tmp_path):
    run = tmp_path / "run"
    code = (f"from unicross.rl.ppo import PPOTrainer\n"
            f"t = PPOTrainer({str(run)!r}, 'grasp', overrides={dict(TINY, collector=dict(total_frames=10**6, horizon=16))!r}, progress=False)\n"
            f"t.train()\n")
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    ckpt = run / "checkpoint.pt"
    deadline = time.time() + 120
    while time.time() < deadline and not ckpt.exists():
        time.sleep(0.2)
    time.sleep(1.0)
    p.send_signal(signal.SIGKILL)
    p.wait()
    assert ckpt.exists()
    r = PPOTrainer(run, resume=True, progress=False, overrides=dict(collector=dict(total_frames=10**6)))
    k = r.iteration
    assert k >= 1
    r.train(max_iterations=1)
    assert r.iteration == k + 1
    r.close()


def test_bad_input_fails_fast(tmp_path):
    with pytest.raises(ValueError, match="valid skills"):
        PPOTrainer(tmp_path / "a", "juggle", progress=False)
    with pytest.raises(ValueError, match="takes no axis"):
        PPOTrainer(tmp_path / "b", "relocate", axis="x+", progress=False)
    with pytest.raises(ValueError, match="valid directions"):
        PPOTrainer(tmp_path / "c", "translate", axis="x+", progress=False)
    with pytest.raises(FileNotFoundError, match="no checkpoint"):
        PPOTrainer(tmp_path / "d", resume=True, progress=False)


def test_ablation_row_is_one_train_and_one_eval(tmp_path):
    import json
    from unicross.cli import main
    run = tmp_path / "abl"
    assert main(["train", "--skill", "grasp", "--out", str(run), "--num-envs", "1", "--total-frames", "32",
                 "--ablation", "no_target_obs", "--set", "collector.horizon=16", "--set", "logging.eval_trials=0", "--set", "logging.final_eval_trials=0",
                 "--set", "env.object_limit=1", "--set", "optim.minibatch_size=16"]) == 0
    out = tmp_path / "abl.json"
    assert main(["eval", "--policy", str(run / "checkpoint.pt"), "--protocol", "grasp", "--objects", "train-wrappable",
                 "--limit", "1", "--trials-per-object", "1", "--out", str(out)]) == 0
    r = json.loads(out.read_text())
    assert r["policy"]["ablation"] == {"no_target_obs": True}
    assert main(["train", "--skill", "grasp", "--out", str(tmp_path / "x"), "--ablation", "no_fun"]) == 2


def test_finished_run_evaluates_on_held_out_objects_and_exports(tmp_path):
    """The end of a run: the paper's protocol on held-out objects (final_eval.json, unicross eval's
    format), and `unicross export` ships the acting part, loadable as a policy."""
    import json
    from unicross.cli import main
    from unicross.rl.policy_io import load_policy
    over = dict(TINY, logging=dict(eval_trials=0, final_eval_trials=1, final_eval_limit=1, checkpoint_every=1))
    t = PPOTrainer(tmp_path / "run", "grasp", overrides=over, progress=False)
    summary = t.train()
    t.close()
    r = json.loads((tmp_path / "run" / "final_eval.json").read_text())
    assert r["objects"] == "test" and r["summaries"]["grasp"]["n"] == 4 == summary["final"]["n"]
    out = tmp_path / "ship" / "grasp.pt"
    gz = tmp_path / "final_eval.json.gz"  # evaluations are committed gzipped
    gz.write_bytes(gzip.compress((tmp_path / "run" / "final_eval.json").read_bytes()))
    assert main(["export", str(tmp_path / "run"), "--out", str(out), "--command", "unicross train ...",
                 "--eval", str(tmp_path / "run" / "final_eval.json"), "--eval", str(gz)]) == 0
    side = json.loads(out.with_suffix(".json").read_text())
    assert side["commands"] == ["unicross train ..."] and side["evaluations"][0]["summaries"]["grasp"]["n"] == 4
    assert side["evaluations"][1]["summaries"] == side["evaluations"][0]["summaries"]
    from unicross.report import cpu_model  # the CPU's model name (platform.processor() is empty on Linux)
    assert side["hardware"]["processor"] == cpu_model() != ""
    policy, ck = load_policy(out)
    assert "optim" not in ck and ck["skill"] == "grasp" and out.stat().st_size < 3e6


def test_set_reads_numbers_the_way_users_write_them():
    from unicross.cli import parse_sets
    got = parse_sets(["optim.lr_min=1e-5", "optim.lr=3.0e-4", "logging.eval_objects=test", "env.object_limit=null"])
    assert got == {"optim": {"lr_min": 1e-5, "lr": 3e-4}, "logging": {"eval_objects": "test"},
                   "env": {"object_limit": None}}
    assert isinstance(got["optim"]["lr_min"], float)


def test_kl_stop_ends_the_epochs_early(tmp_path):
    """``optim.kl_stop`` ends an update at the first minibatch whose KL passes it; unset, every
    minibatch of every epoch runs (16 frames / minibatch 8 x 2 epochs = 4 steps)."""
    import copy
    full = PPOTrainer(tmp_path / "full", "grasp", overrides=TINY, progress=False)
    full.train(max_iterations=1)
    full.close()
    cfg = copy.deepcopy(TINY)
    cfg["optim"]["kl_stop"] = -1.0  # any KL passes it: one step per update
    stop = PPOTrainer(tmp_path / "stop", "grasp", overrides=cfg, progress=False)
    stop.train(max_iterations=1)
    stop.close()
    import json
    steps = {name: json.loads((tmp_path / name / "metrics.jsonl").read_text().splitlines()[0])["minibatch_steps"]
             for name in ("full", "stop")}
    assert steps == {"full": 4, "stop": 1}


def test_resumed_run_with_more_frames_replaces_its_final_evaluation(tmp_path):
    """A finished run resumed with a larger ``collector.total_frames`` trains on and evaluates the
    policy it ends with (the earlier ``final_eval.json`` had kept the first run's result); a resume
    that trains nothing keeps the evaluation it has, and does the one that is missing."""
    import json
    run = tmp_path / "run"
    ev = dict(TINY["logging"], final_eval_trials=1, final_eval_limit=1)
    t = PPOTrainer(run, "grasp", overrides=dict(TINY, collector=dict(total_frames=32, horizon=16), logging=ev),
                   progress=False)
    try:
        assert t.train()["final"]["n"] > 0
    finally:
        t.close()
    assert json.loads((run / "final_eval.json").read_text())["frames"] == 32
    t = PPOTrainer(run, resume=True, overrides=dict(collector=dict(total_frames=48)), progress=False)
    try:
        assert "final" in t.train() and t.frames == 48
    finally:
        t.close()
    assert json.loads((run / "final_eval.json").read_text())["frames"] == 48
    t = PPOTrainer(run, resume=True, overrides=dict(collector=dict(total_frames=48)), progress=False)
    try:
        assert "final" not in t.train()
    finally:
        t.close()
    (run / "final_eval.json").unlink()  # e.g. stopped during its final evaluation: a resume does it
    t = PPOTrainer(run, resume=True, progress=False)
    try:
        assert "final" in t.train() and t.frames == 48
    finally:
        t.close()
    assert json.loads((run / "final_eval.json").read_text())["frames"] == 48
