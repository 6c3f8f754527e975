"""Nothing lost, nothing silent: signals, failed segments, resumed logs, contradictions, config
types and ranges, seeds of any size (issue "Nothing lost, nothing silent")."""
import json
import os
import signal
import subprocess
import sys
import time

import pytest
import torch

from unicross.cli import main as cli
from unicross.config import load_config
from unicross.rl.ppo import PPOTrainer

TINY = dict(env=dict(num_envs=1, object_limit=1), collector=dict(total_frames=96, horizon=16),
            optim=dict(minibatch_size=8, mini_epochs=2), logging=dict(eval_trials=0, final_eval_trials=0, checkpoint_every=1))
TINY_SETS = ["env.num_envs=1", "env.object_limit=1", "collector.horizon=16", "optim.minibatch_size=8",
             "optim.mini_epochs=2", "logging.eval_trials=0", "logging.final_eval_trials=0", "logging.checkpoint_every=100"]


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_saves_the_last_iteration_and_exits_with_one_line(tmp_path, sig):
    run = tmp_path / "run"
    cmd = [sys.executable, "-m", "unicross.cli", "train", "--skill", "grasp", "--out", str(run),
           "--total-frames", "100000"] + [a for s in TINY_SETS for a in ("--set", s)]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env=dict(os.environ, UNICROSS_COMPILE="0"))
    metrics = run / "metrics.csv"
    deadline = time.time() + 240
    while time.time() < deadline and (not metrics.exists() or len(metrics.read_text().splitlines()) < 3):
        time.sleep(0.2)
    p.send_signal(sig)
    out, err = p.communicate(timeout=120)
    assert p.returncode == 128 + int(sig), err[-2000:]
    assert "Traceback" not in err and "Traceback" not in out
    assert f"stopped by {signal.Signals(sig).name}" in err
    ck = torch.load(run / "checkpoint.pt", weights_only=False)  # checkpoint_every=100: written by the stop
    rows = metrics.read_text().strip().splitlines()[1:]
    assert ck["iteration"] == len(rows) >= 2


@pytest.fixture()
def tiny_run(tmp_path):
    run = tmp_path / "run"
    t = PPOTrainer(run, "grasp", overrides=TINY, progress=False)
    t.train(max_iterations=2)
    t.close()
    return run


def test_a_failed_segment_leaves_the_checkpoint_as_it_was(tiny_run, monkeypatch):
    before = (tiny_run / "checkpoint.pt").read_bytes()
    r = PPOTrainer(tiny_run, resume=True, progress=False,
                   overrides=dict(env=dict(task_config=dict(randomization=dict(perturb_scale=3.0)))))

    def boom():
        raise RuntimeError("collection failed")
    monkeypatch.setattr(r.collector, "collect", boom)
    with pytest.raises(RuntimeError, match="collection failed"):
        r.train(max_iterations=1)
    r.close()
    assert (tiny_run / "checkpoint.pt").read_bytes() == before
    ck = torch.load(tiny_run / "checkpoint.pt", weights_only=False)
    assert ck["config"]["env"]["task_config"].get("randomization") is None  # the failed override is not kept


def test_a_non_finite_loss_stops_the_run_and_keeps_the_checkpoint(tiny_run, monkeypatch):
    before = (tiny_run / "checkpoint.pt").read_bytes()
    r = PPOTrainer(tiny_run, resume=True, progress=False)
    monkeypatch.setattr(r.algo, "update", lambda data: dict(loss_objective=float("nan"), kl=0.0))
    with pytest.raises(RuntimeError, match="non-finite loss_objective at iteration 3"):
        r.train(max_iterations=1)
    r.close()
    assert (tiny_run / "checkpoint.pt").read_bytes() == before


def test_resume_cuts_the_logs_back_to_the_checkpoint(tiny_run):
    # what a run killed with -9 leaves: rows logged after its last checkpoint
    with open(tiny_run / "metrics.jsonl", "a") as f:
        f.write(json.dumps(dict(iteration=3, frames=48)) + "\n")
    with open(tiny_run / "metrics.csv", "a") as f:
        f.write("3" + "," * (len((tiny_run / "metrics.csv").read_text().splitlines()[0].split(",")) - 1) + "\n")
    r = PPOTrainer(tiny_run, resume=True, progress=False)
    r.train(max_iterations=1)
    r.close()
    iters = [json.loads(line)["iteration"] for line in (tiny_run / "metrics.jsonl").read_text().splitlines()]
    assert iters == [1, 2, 3]
    assert [line.split(",")[0] for line in (tiny_run / "metrics.csv").read_text().splitlines()[1:]] == ["1", "2", "3"]


def test_resume_refuses_contradictions_and_applies_what_may_change(tiny_run, capsys):
    with pytest.raises(ValueError, match="cannot resume .* --skill rotate"):
        PPOTrainer(tiny_run, "rotate", axis="x+", resume=True, progress=False)
    with pytest.raises(ValueError, match="--hand mano"):
        PPOTrainer(tiny_run, hand="mano", resume=True, progress=False)
    r = PPOTrainer(tiny_run, resume=True, progress=False, overrides=dict(optim=dict(lr=1.0e-5), env=dict(num_envs=2)))
    assert r.algo.lr == 1.0e-5 and all(g["lr"] == 1.0e-5 for g in r.algo.optim.param_groups)
    r.close()
    said = capsys.readouterr().out
    assert "optim.lr=1e-05" in said and "env.num_envs=2 (was 1)" in said
    assert cli(["train", "--out", str(tiny_run), "--resume", "--skill", "relocate"]) == 2


@pytest.mark.unit
def test_config_values_have_their_kind_and_range():
    with pytest.raises(ValueError, match="'optim.lr' expects a number"):
        load_config("ppo", dict(optim=dict(lr="abc")))
    assert load_config("ppo", dict(collector=dict(total_frames=1e6)))["collector"]["total_frames"] == 1000000
    with pytest.raises(ValueError, match="whole number"):
        load_config("ppo", dict(optim=dict(mini_epochs=2.5)))
    bad = [("task", dict(randomization=dict(mass=[-0.01, 0.04]))), ("task", dict(randomization=dict(friction=[-1.0, 3.0]))),
           ("task", dict(sim=dict(sim_freq=0))), ("task", dict(randomization=dict(mass=[0.04, 0.002]))),
           ("ppo", dict(collector=dict(total_frames=0))), ("ppo", dict(env=dict(object_limit=-1))),
           ("ppo", dict(gae=dict(gamma=float("nan")))), ("ppo", dict(optim=dict(lr=-1.0))),
           ("dagger", dict(optim=dict(epochs=0))), ("task", dict(episode_length=dict(grasp=0)))]
    for name, override in bad:
        with pytest.raises(ValueError, match="must be|range"):
            load_config(name, override)


def test_bad_values_are_refused_before_any_worker_starts(tmp_path):
    t0 = time.time()
    assert cli(["train", "--skill", "grasp", "--out", str(tmp_path / "a"), "--set", "optim.lr=abc"]) == 2
    assert cli(["train", "--skill", "grasp", "--out", str(tmp_path / "b"),
                "--set", "env.task_config={randomization: {mass: [-1.0, 0.04]}}"]) == 2
    assert cli(["train", "--skill", "grasp", "--out", str(tmp_path / "c"), "--total-frames", "0"]) == 2  # >= 1
    assert time.time() - t0 < 30
    assert not (tmp_path / "a" / "checkpoint.pt").exists()


def test_eval_takes_any_seed_a_user_types(tmp_path):
    out = tmp_path / "e.json"
    assert cli(["eval", "--policy", "zero", "--protocol", "grasp", "--objects", "test", "--limit", "1",
                "--trials-per-object", "1", "--seed", "9173", "--out", str(out)]) == 0
    r = json.loads(out.read_text())
    assert all(0 <= t["seed"] < 2 ** 32 for t in r["trials"]["grasp"])


@pytest.mark.unit
def test_torch_is_a_range_so_a_cuda_build_stays():
    import re
    from pathlib import Path
    text = (Path(__file__).resolve().parent.parent / "pyproject.toml").read_text()
    torch_req = re.search(r'"torch([^"]*)"', text).group(1)
    assert torch_req.startswith(">=") and "==" not in torch_req


def test_eval_keeps_finished_protocols_and_resumes(tmp_path, monkeypatch):
    """A protocol that fails keeps the finished ones on disk; --resume runs only the rest; an
    --out that cannot be written fails before any simulation."""
    from unicross import evaluation as E
    out = tmp_path / "e.json"
    args = ["eval", "--policy", "zero", "--protocol", "grasp,relocate", "--objects", "test", "--limit", "1",
            "--trials-per-object", "1", "--out", str(out)]
    real = E.run_protocol_workers

    def fail_relocate(protocol, *a, **k):
        if protocol == "relocate":
            raise RuntimeError("interrupted")
        return real(protocol, *a, **k)
    monkeypatch.setattr(E, "run_protocol_workers", fail_relocate)
    assert cli(args) == 2
    kept = json.loads(out.read_text())
    assert list(kept["trials"]) == ["grasp"] and len(kept["trials"]["grasp"]) == 4
    calls = []

    def count(protocol, *a, **k):
        calls.append(protocol)
        return real(protocol, *a, **k)
    monkeypatch.setattr(E, "run_protocol_workers", count)
    assert cli(args + ["--resume"]) == 0
    assert calls == ["relocate"]
    done = json.loads(out.read_text())
    assert done["trials"]["grasp"] == kept["trials"]["grasp"] and len(done["trials"]["relocate"]) > 0
    assert cli(args[:-1] + [str(tmp_path), "--resume"]) == 2  # a directory
    blocker = tmp_path / "file"
    blocker.write_text("")
    t0 = time.time()
    assert cli(args[:-1] + [str(blocker / "e.json")]) == 2  # under a file
    assert time.time() - t0 < 20
    assert cli(args + ["--resume", "--seed", "3"]) == 2  # other settings


def test_user_errors_are_one_line_before_any_simulation(tmp_path, capsys):
    garbage = tmp_path / "garbage.pt"
    garbage.write_text("not a checkpoint\n")
    run = tmp_path / "run"
    run.mkdir()
    cases = [
        (["eval", "--policy", str(garbage), "--protocol", "grasp", "--out", str(tmp_path / "o.json")], "not a UniCross checkpoint"),
        (["eval", "--policy", str(run), "--protocol", "grasp", "--out", str(tmp_path / "o.json")], "is a directory"),
        (["chain", "--policy", str(garbage)], "not a UniCross checkpoint"),
        (["grasps", "--expert", str(garbage), "--out", str(tmp_path / "g.pt")], "not a UniCross checkpoint"),
        (["grasps", "--chain", "grasp,relocate", "--out", str(tmp_path / "g.pt")], "--chain needs --policy"),
        (["grasps", "--chain", "relocate,translate:z+", "--policy", "zero", "--out", str(tmp_path / "g.pt")],
         "a chain starts with a skill that starts from the table"),
        (["grasps", "--chain", "grasp,relocate", "--policy", str(garbage), "--out", str(tmp_path / "g.pt")],
         "not a UniCross checkpoint"),
        (["eval", "--policy", "zero", "--protocol", "relocate", "--grasps", str(garbage), "--limit", "1",
          "--out", str(tmp_path / "o.json")], "not a UniCross grasp dataset"),
        (["rollout", "--task", "Nope-v1"], "unknown task"),
        (["train", "--skill", "rotate", "--out", str(tmp_path / "r")], "rotate needs --axis"),
        (["train", "--skill", "grasp", "--out", str(garbage / "x")], "cannot make the run directory"),
        (["rollout", "--task", "UniCross-Grasp-v1", "--axis", "y-"], "takes no --axis"),
        (["render", str(garbage), "--out", str(tmp_path / "v.mp4"), "--size", "big"], "WIDTHxHEIGHT"),
        (["render", str(garbage), "--out", str(tmp_path / "v.mp4")], "not a UniCross trajectory file"),
    ]
    for argv, message in cases:
        assert cli(argv) == 2, argv
        err = capsys.readouterr().err
        assert message in err and "Traceback" not in err, (argv, err)
    assert not (tmp_path / "r").exists()  # refused before the run directory was made


def test_every_mode_has_an_id_and_the_control_mode_is_named():
    """Clients that cannot pass env kwargs (ManiSkill's PPO baseline) make a mode by id; a
    ManiSkill default control mode gets a one-line hint."""
    import gymnasium as gym
    import unicross
    from unicross import formulation as F
    assert len(unicross.AXIS_TASK_IDS) == sum(1 for m in F.MODES if "_" in m)
    env = gym.make("UniCross-TranslateZNeg-v1", obs_mode="state", sim_backend="physx_cpu", render_backend="none",
                   object_limit=1)
    env.reset(seed=0)
    assert F.MODES[int(env.unwrapped.mode)] == "translate_z-"
    env.close()
    with pytest.raises(ValueError, match="--control_mode pd_joint_pos"):
        gym.make("UniCross-Grasp-v1", control_mode="pd_joint_delta_pos")


def test_recorded_env_states_replay_to_the_same_observations(tmp_path):
    """ManiSkill's RecordEpisode stores env states; restoring each (batched, or unbatched as
    ManiSkill's replay_trajectory --use-env-states passes them) gives the recorded observation."""
    import gymnasium as gym
    import h5py
    from mani_skill.utils.wrappers.record import RecordEpisode
    kw = dict(obs_mode="state", sim_backend="physx_cpu", render_backend="none", object_limit=1)
    env = RecordEpisode(gym.make("UniCross-Relocate-v1", **kw), output_dir=str(tmp_path), save_video=False,
                        save_trajectory=True, trajectory_name="t", record_env_state=True)
    obs, _ = env.reset(seed=0)
    seen = [obs.clone()]
    g = torch.Generator().manual_seed(0)
    for _ in range(12):
        obs, *_ = env.step(torch.rand(22, generator=g) * 2 - 1)
        seen.append(obs.clone())
    env.close()

    def state(group, i):
        batch = (lambda x: x[None]) if i % 2 else (lambda x: x)
        return {k: state(v, i) if isinstance(v, h5py.Group) else batch(torch.tensor(v[i])) for k, v in group.items()}
    replay = gym.make("UniCross-Relocate-v1", **kw)
    replay.reset(seed=0)
    u = replay.unwrapped
    with h5py.File(tmp_path / "t.h5") as f:
        states = f["traj_0"]["env_states"]
        for i, o in enumerate(seen):
            u.set_state_dict(state(states, i))
            assert torch.allclose(u.get_obs(), o, atol=1e-5), i
    replay.close()


def test_mixed_batches_and_the_state_registry_hold_on_cpu():
    """Found by reading against ManiSkill's GPU path, checked where the CPU can: a grasp-mode env
    whose object has no grasp state no longer crashes a mixed-mode env (its grasp was sampled
    although unused); the merged object is one entry of the state registry (as pick_single_ycb.py);
    a GPU run that rebuilds scenes is refused before any simulation."""
    import gymnasium as gym
    from unicross.objects import get_object_set
    objs = [o for o in get_object_set("unseen") if o.name in ("wrappable-sphere-unseen-000", "wrappable-sphere-unseen-001")]
    env = gym.make("UniCross-MultiSkill-v1", obs_mode="state", sim_backend="physx_cpu", render_backend="none",
                   objects=objs, modes=["grasp", "relocate"])
    u = env.unwrapped
    for s in range(6):  # seeds 3-5 start the grasp mode on the sphere that has no grasp
        env.reset(seed=s)
    assert list(u.get_state_dict()["actors"]) == ["object"]  # was "object-0" (the per-env actor)
    env.close()
    with pytest.raises(ValueError, match="reconfiguration_freq must be 0"):
        gym.make("UniCross-Grasp-v1", sim_backend="physx_cuda", reconfiguration_freq=4)


def test_the_readme_eval_example_runs_as_written(tmp_path):
    """README, Commands: `unicross eval --policy zero --protocol all --objects test` (here one object
    per group and one trial): every protocol runs with the shipped grasp set."""
    out = tmp_path / "all.json"
    assert cli(["eval", "--policy", "zero", "--protocol", "all", "--objects", "test", "--limit", "1",
                "--trials-per-object", "1", "--out", str(out)]) == 0
    assert set(json.loads(out.read_text())["trials"]) == {"grasp", "relocate", "rotate", "translate"}


def test_help_does_not_import_the_simulator():
    """`import unicross` registers the ids lazily: the CLI's help needs no ManiSkill, SAPIEN or torch."""
    code = ("import sys, unicross.cli\n"
            "assert unicross.cli.main(['--help']) == 0\n"
            "heavy = [m for m in ('mani_skill', 'sapien', 'torch') if m in sys.modules]\n"
            "assert not heavy, heavy\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr[-1500:]
    assert "unicross train" in out.stdout
