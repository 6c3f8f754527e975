"""Skill chaining: mode switches at the right step, continuous state across the switch, per-phase success."""
import pytest
import torch

from conftest import make
from unicross import formulation as F
from unicross.scripted_grasp import ScriptedGrasp
from unicross.tasks.chain import parse_sequence


def test_sequence_parsing():
    assert parse_sequence("grasp,relocate,rotate:x+") == ["grasp", "relocate", "rotate_x+"]
    with pytest.raises(ValueError, match="valid axes"):
        parse_sequence("grasp,rotate:w+")
    with pytest.raises(ValueError, match="starts from the table"):
        parse_sequence("relocate,rotate:x+")


def _grasping_chain(sequence: str, seed: int, **phase_steps):
    """A one-env chain on a test wrappable object, reset with ``seed``, and the scripted grasp acting on it."""
    env = make("UniCross-Chain-v1", objects="test-wrappable", sequence=sequence, phase_steps=phase_steps,
               randomize=False)
    env.reset(seed=seed)
    return env, env.unwrapped, ScriptedGrasp(env.unwrapped)


def test_chain_switches_modes_continuously():
    env, u, policy = _grasping_chain("grasp,relocate,rotate:y-", 1, grasp=60, relocate=10, rotate=10)
    assert u.phase_ends == [60, 70, 80] and u.mode.item() == F.MODES.index("grasp")
    modes, info = [], None
    for t in range(80):
        a = policy() if t < 55 else torch.zeros(1, 22)
        root_before = u.root_p.clone()
        _, _, term, trunc, info = env.step(a)
        modes.append(u.mode.item())
        if t + 1 in (60, 70):  # the switch happened inside this step: compare the state it left
            mid = u.agent.robot.get_qpos()
            assert torch.count_nonzero(mid[:, u._qidx[:6]]) == 0            # virtual joints re-based to zero
            assert not torch.allclose(u.root_p, root_before)               # new root frame = current hand
            assert torch.allclose(u.cur_rel.x_hr, torch.zeros(1, 3), atol=1e-5)
        if term.any():
            break
    assert modes[:59] == [0] * 59 and modes[59] == F.MODES.index("relocate")
    assert modes[69] == F.MODES.index("rotate_y-")
    assert (trunc.all() or term.all()) and info["phase"].item() == 2  # ends at the last phase's end or on a drop
    assert info["phase_success"].shape == (1, 3) and info["phase_success"][0, 0]  # the scripted grasp lifted it


def test_no_teleport_across_the_switch():
    env, u, policy = _grasping_chain("grasp,relocate", 2, grasp=58, relocate=5)
    for _ in range(57):
        env.step(policy())
    # step 58 ends the grasp phase; record the world state right before the switch is applied
    from unicross.tasks import chain as C
    seen = {}
    orig = C.ChainEnv._switch_phase

    def spy(self, k):
        seen["before"] = [t.clone() for t in self.sensor.poses()]
        seen["vel_before"] = self.agent.robot.links[0].get_linear_velocity().clone()
        orig(self, k)
        seen["after"] = [t.clone() for t in self.sensor.poses()]
    C.ChainEnv._switch_phase = spy
    try:
        env.step(torch.zeros(22))
    finally:
        C.ChainEnv._switch_phase = orig
    (p0, q0), (p1, q1) = seen["before"], seen["after"]
    assert torch.allclose(p0, p1, atol=1e-5)                  # every link and the object stay put
    assert torch.allclose(q0.abs(), q1.abs(), atol=1e-5)
    hand = next(l for l in u.agent.robot.links if l.name == "hand_frame")
    # velocities carry over: stepping on, the hand keeps moving smoothly (no jump)
    v_after = hand.get_linear_velocity().clone()
    env.step(torch.zeros(22))
    v_next = hand.get_linear_velocity()
    assert (v_next - v_after).norm() < 0.5


def test_chain_command_runs_a_policy_and_writes_every_trial(tmp_path):
    import json
    from unicross.cli import main as cli
    out = tmp_path / "chain.json"
    assert cli(["chain", "--policy", "zero", "--sequence", "grasp,relocate", "--objects", "test-wrappable",
                "--limit", "1", "--out", str(out)]) == 0
    r = json.loads(out.read_text())
    assert r["policy"]["kind"] == "zero" and len(r["trials"]) >= 1
    assert all(len(t["phase_success"]) == 2 for t in r["trials"])


def test_a_fixed_sequence_runs_on_the_objects_that_can_do_it():
    """``unicross chain --sequence grasp,rotate:x+`` on a set with sticks runs the wrappable objects and
    leaves the sticks out (it used to stop with an error at the first stick, after the trials before it,
    writing nothing); a set with no object for the sequence fails before any simulation."""
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    stick, ball = get_object_set("test-elongated", limit=1)[0], get_object_set("test-wrappable", limit=1)[0]
    zero, _ = E.resolve_policy("zero", "allegro")
    trials = E.run_chain(zero, [stick, ball], "grasp,rotate:x+", trials_per_object=1, progress=False)
    assert [t["object"] for t in trials] == [ball.name]
    with pytest.raises(ValueError, match="no object of the set can do every phase"):
        E.run_chain(zero, [stick], "grasp,rotate:x+", trials_per_object=1, progress=False)


def test_an_in_hand_phase_that_drops_after_its_threshold_fails():
    """The per-skill protocol counts a rotation past pi/2 only if the object is never dropped in the
    episode; the chain's in-hand phase does too: a drop after the threshold takes the success back."""
    env, u, policy = _grasping_chain("grasp,rotate:y-", 1, grasp=60, rotate=20)
    for t in range(60):
        env.step(policy() if t < 55 else torch.zeros(1, 22))
    assert u.phase.item() == 1 and u.phase_success[0, 0]  # lifted, now in the rotate phase
    u.rot_acc = torch.full_like(u.rot_acc, 2.0)  # past pi/2 (as if turned)
    _, _, term, _, info = env.step(torch.zeros(1, 22))
    assert not term.any() and info["phase_success"][0, 1]
    from mani_skill.utils.structs.pose import Pose
    p = u.obj.pose.p.clone()
    p[:, 2] += 1.0  # the object leaves the hand
    u.obj.set_pose(Pose.create_from_pq(p, u.obj.pose.q))
    _, _, term, _, info = env.step(torch.zeros(1, 22))
    assert term.all() and info["drop"].all()
    assert not info["phase_success"][0, 1] and info["phase_success"][0, 0]


def test_chain_state_round_trip_keeps_the_phase():
    """The phase and phase successes are task state: restoring a state taken in the second phase
    after the episode moved on to the third brings the phase and mode back."""
    env = make("UniCross-Chain-v1", objects="test-wrappable", sequence="grasp,relocate,rotate:y-",
               phase_steps=dict(grasp=3, relocate=3, rotate=3), randomize=False)
    u = env.unwrapped
    env.reset(seed=1)
    for _ in range(4):
        env.step(torch.zeros(22))
    assert u.phase.tolist() == [1] and u.mode.item() == F.MODES.index("relocate")
    state, obs = u.get_state_dict(), u.get_obs()
    for _ in range(3):
        _, _, _, _, info = env.step(torch.zeros(22))
    assert info["phase"].tolist() == [2]
    u.set_state_dict(state)
    assert u.phase.tolist() == [1] and u.mode.item() == F.MODES.index("relocate")
    assert torch.allclose(u.get_obs(), obs, atol=1e-5)
    env.close()


def test_last_phase_by_mode_splits_a_sequence_kind_by_its_in_hand_mode():
    from unicross.evaluation import chain_last_phase_by_mode
    t = lambda m, ok: dict(sequence=["grasp", "relocate", m], phase_success=[True, True, ok])  # noqa: E731
    s = chain_last_phase_by_mode([t("translate_z+", True), t("translate_z+", True), t("translate_z-", False),
                                  t("translate_z+", False)])
    assert list(s) == ["translate_z+", "translate_z-"]
    assert (s["translate_z+"]["n"], s["translate_z+"]["successes"]) == (3, 2) and s["translate_z-"]["sr"] == 0.0


def test_experts_policy_acts_with_the_expert_of_each_phase(tmp_path):
    """``experts:allegro`` (or a distill-style folder) switches expert at each phase boundary: every
    action is the current mode's shipped expert's; a wrong folder fails before any simulation."""
    from unicross.evaluation import resolve_policy
    fn, desc = resolve_policy("experts:allegro", "allegro")
    assert desc["kind"] == "experts" and desc["experts"]["rotate_y-"] == "allegro/rotate_y-"
    single = {m: resolve_policy(f"allegro/{m}", "allegro")[0] for m in ("grasp", "relocate", "rotate_y-")}
    env = make("UniCross-Chain-v1", objects="test-wrappable", sequence="grasp,relocate,rotate:y-",
               phase_steps=dict(grasp=3, relocate=3, rotate=3), randomize=False, obs_mode="state_dict")
    u = env.unwrapped
    obs, _ = u.reset(seed=1)
    seen = []
    try:
        for _ in range(8):
            m = F.MODES[u.mode.item()]
            seen.append(m)
            a = fn(obs, u)
            torch.testing.assert_close(a, single[m](obs, u))
            assert all((a - single[o](obs, u)).abs().max() > 1e-4 for o in single if o != m)
            obs, *_ = u.step(a)
    finally:
        env.close()
    assert seen == ["grasp"] * 3 + ["relocate"] * 3 + ["rotate_y-"] * 2
    with pytest.raises(FileNotFoundError, match="neither a folder"):
        resolve_policy(f"experts:{tmp_path / 'none'}", "allegro")
    with pytest.raises(FileNotFoundError, match="no expert checkpoint"):
        resolve_policy(f"experts:{tmp_path}", "allegro")
    import shutil
    from unicross.rl.policy_io import SHIPPED_DIR
    for m in F.MODES:  # every folder holds the grasp expert: the wrong mode is named
        (tmp_path / m).mkdir()
        shutil.copy(SHIPPED_DIR / "allegro" / "grasp.pt", tmp_path / m / "checkpoint.pt")
    with pytest.raises(ValueError, match="trained for mode 'grasp', not 'relocate'"):
        resolve_policy(f"experts:{tmp_path}", "allegro")
