"""The skill registry is the one place skills are defined: everything else derives from it."""
import pytest
from mani_skill.utils.registration import REGISTERED_ENVS
import torch

import unicross  # noqa: F401  (registers the task ids)
import unicross.tasks.skills  # noqa: F401  (the task classes, registered with ManiSkill too)
from unicross import formulation as F
from unicross import registry as R
from unicross.config import load_config
from unicross.rl.policy_io import check_modes, load_policy


@pytest.mark.unit
def test_modes_goal_and_axes_follow_the_registry():
    assert F.MODES == tuple(m for s in R.SKILLS.values() for m in s.modes)
    assert F.GOAL_DIM == len(F.MODES) + 3 + 2 * 21
    for i, m in enumerate(F.MODES):
        sk = R.skill_of_mode(m)
        assert F.SKILLS[int(F.MODE_SKILL_ID[i])] == sk.name
        axis = R.mode_axis(m)
        assert F.mode_index(sk.name, axis) == i
        assert torch.equal(F.MODE_AXES[i], torch.tensor(R.axis_vector(axis)))
    assert F.SKILL_TARGETS == {s.name: s.targets for s in R.SKILLS.values()}


@pytest.mark.unit
def test_every_skill_is_a_registered_task_with_its_configured_length():
    lengths = load_config("task")["episode_length"]
    for s in R.SKILLS.values():
        assert REGISTERED_ENVS[s.env_id].max_episode_steps == lengths[s.name]
        assert set(s.targets) == set(F.SLOTS)


@pytest.mark.unit
def test_axes_are_validated_with_the_valid_values_listed():
    with pytest.raises(ValueError, match=r"valid axes: \['x\+'"):
        R.skill("rotate").mode("w+")
    with pytest.raises(ValueError, match="valid directions"):
        R.skill("translate").env_kwargs(None)
    with pytest.raises(ValueError, match="takes no axis"):
        R.skill("grasp").mode("z+")
    with pytest.raises(ValueError, match="valid skills"):
        R.skill("juggle")
    assert R.skill("translate").env_kwargs("z-") == {"direction": "z-"}


@pytest.mark.unit
def test_checkpoints_of_another_registry_are_refused():
    _, ck = load_policy("allegro/grasp")
    check_modes(ck, "allegro/grasp")  # the shipped checkpoints match this registry
    other = dict(ck, modes=list(F.MODES) + ["translate_x+"], obs_dims=dict(ck["obs_dims"], goal=F.GOAL_DIM + 1))
    with pytest.raises(ValueError, match="retrain it"):
        check_modes(other, "other.pt")
    reordered = dict(ck, modes=list(reversed(F.MODES)))
    with pytest.raises(ValueError, match="skill registry"):
        check_modes(reordered, "reordered.pt")


def test_a_new_reward_term_is_one_registered_function(monkeypatch):
    """A throwaway term shows up in the reward, in info, in the RL env's keys and in the logs."""
    import gymnasium as gym
    from unicross import rewards
    from unicross.rl.env import ManiSkillEnv, info_float_keys
    from unicross.rl.ppo import csv_fields

    monkeypatch.setattr(rewards, "REGISTRY", dict(rewards.REGISTRY))  # restored after the test
    rewards.reward_term("bonus", lambda cfg, dev: dict(w=0.5))(lambda m, c, mode: c["w"] * torch.ones_like(m["drop"].float()))
    assert "reward_bonus" in info_float_keys() and "reward_bonus" in csv_fields()
    env = gym.make("UniCross-Grasp-v1", obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none",
                   num_envs=1, object_limit=1)
    u = env.unwrapped
    u.reset(seed=0)
    _, reward, _, _, info = u.step(torch.zeros(1, u.hand_spec.dof))
    assert torch.allclose(info["reward_bonus"], torch.tensor([0.5]))
    others = sum(info[f"reward_{t}"] for t in rewards.term_names() if t != "bonus")
    assert torch.allclose(reward, others + 0.5)
    env.close()
    with pytest.raises(ValueError, match="twice"):
        rewards.reward_term("bonus", lambda cfg, dev: {})(lambda m, c, mode: None)
    tr = ManiSkillEnv("UniCross-Grasp-v1", dict(object_limit=1))
    assert ("info", "reward_bonus") in tr.observation_spec.keys(include_nested=True)
    td = tr.rollout(2)
    assert torch.allclose(td["next", "info", "reward_bonus"], torch.full((2, 1), 0.5))
    assert torch.allclose(td["next", "reward"], sum(td["next", "info", f"reward_{t}"] for t in rewards.term_names()))
    tr.close()


@pytest.mark.unit
def test_every_skill_names_a_registered_success_test():
    from unicross import success as S
    for s in R.SKILLS.values():
        assert S.get(s.success) is S.SUCCESS_TESTS[s.success]
    with pytest.raises(ValueError, match="registered"):
        S.get("no_such_test")


def test_a_new_observation_term_is_one_function_and_one_config_line(monkeypatch):
    """A throwaway term named in the config's object group reaches the observation, the RL env's
    spec and the policy's input sizes; unknown terms are refused before any simulation."""
    import gymnasium as gym
    from unicross import observations as O
    from unicross.rl.env import ManiSkillEnv

    monkeypatch.setattr(O, "OBSERVATION_TERMS", dict(O.OBSERVATION_TERMS))
    O.observation_term("object_speed")(lambda env: torch.linalg.norm(env.obj_vel_h, dim=-1, keepdim=True))
    layout = dict(hand=["joint_pos", "command"], object=["contact", "force", "distance", "object_speed"], goal=["goal"])
    kw = dict(object_limit=1, config=dict(observation=layout))
    env = gym.make("UniCross-Grasp-v1", obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none", **kw)
    obs, _ = env.reset(seed=0)
    assert list(obs["extra"]["object"]) == layout["object"] and obs["extra"]["object"]["object_speed"].shape == (1, 1)
    env.close()
    plain = ManiSkillEnv("UniCross-Grasp-v1", dict(object_limit=1))
    tr = ManiSkillEnv("UniCross-Grasp-v1", kw)
    assert tr.observation_spec["object"].shape[-1] == plain.observation_spec["object"].shape[-1] + 1
    plain.close()
    tr.close()
    with pytest.raises(ValueError, match="unknown observation term"):
        gym.make("UniCross-Grasp-v1", object_limit=1, config=dict(observation=dict(layout, goal=["nope"])))


def test_a_new_axis_is_one_registry_entry(tmp_path):
    """A throwaway third translate direction (x+), added to the registry entry alone (in a fresh
    process, since the modes are fixed at import), gives an 11-mode formulation whose env runs."""
    import subprocess
    import sys
    import textwrap
    code = textwrap.dedent('''
        import dataclasses, importlib.util, sys
        # the registry module on its own, patched before the package (and its formulation) imports it
        spec = importlib.util.spec_from_file_location("unicross.registry", REGISTRY_PATH)
        R = importlib.util.module_from_spec(spec)
        sys.modules["unicross.registry"] = R
        spec.loader.exec_module(R)
        skills = [dataclasses.replace(s, axes=s.axes + ("x+",)) if s.name == "translate" else s for s in R._SKILL_LIST]
        R._SKILL_LIST = tuple(skills)
        R.SKILLS = {s.name: s for s in skills}
        R.MODES = tuple(m for s in skills for m in s.modes)
        R.NUM_MODES = len(R.MODES)
        import gymnasium as gym
        import torch
        import unicross
        from unicross import formulation as F
        assert F.NUM_MODES == 11 and F.GOAL_DIM == 11 + 3 + 42 and F.MODES[-1] == "translate_x+"
        env = gym.make("UniCross-Translate-v1", obs_mode="state_dict", sim_backend="physx_cpu",
                       render_backend="none", direction="x+", object_limit=2)
        obs, _ = env.reset(seed=0)
        obs, *_ = env.step(torch.zeros(1, env.unwrapped.hand_spec.dof))
        goal = obs["extra"]["goal"][0]
        assert goal.shape == (F.GOAL_DIM,) and goal[10] == 1 and torch.equal(goal[11:14], torch.tensor([1.0, 0, 0]))
        print("ok")
    ''')
    code = code.replace("REGISTRY_PATH", repr(R.__file__))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600,
                         env=dict(__import__("os").environ, UNICROSS_COMPILE="0"))
    assert out.stdout.strip().endswith("ok"), out.stderr[-2000:]
