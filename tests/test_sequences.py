"""Finger sequences (``unicross.sequences``): parsing, clock windows, per-env state triggers."""
from types import SimpleNamespace

import pytest
import torch

from robots.hand import load_hand
from unicross.audit import finger_sweep_action
from unicross.sequences import check_sequence, make_sequence_policy, parse_sequence


def _env(n=3):
    spec = load_hand("allegro")
    return SimpleNamespace(hand_spec=spec, num_envs=n, device="cpu", elapsed_steps=torch.zeros(n, dtype=torch.int32),
                           command=torch.zeros(n, spec.dof))


@pytest.mark.parametrize("spec, msg", [("index:2:0.05:0", "finger:k:rate:t0:t1"),
                                       ("index:two:0.05:0:10", "integers"),
                                       ("index:0:0.05:0:10", ">= 1"),
                                       ("index:2:0.05:@ring:high", "numbers")])
def test_malformed_sequences_are_refused(spec, msg):
    with pytest.raises(ValueError, match=msg):
        parse_sequence(spec)


def test_fingers_are_checked_against_the_hand():
    spec = load_hand("allegro")
    with pytest.raises(ValueError, match="no finger 'pinky'"):
        check_sequence("pinky:2:0.05:0:10", spec)
    with pytest.raises(ValueError, match="no finger 'pinky'"):
        check_sequence("index:2:0.05:@pinky:0.9", spec)
    with pytest.raises(ValueError, match="has 4 joints"):
        check_sequence("index:5:0.05:0:10", spec)


def test_clock_window_and_state_trigger_per_env():
    u = _env()
    policy = make_sequence_policy("index:2:0.05:0:2+ring:2:0.05:@index:0.9")
    index = finger_sweep_action(u.hand_spec, 0.05, ("index", 2))
    ring = finger_sweep_action(u.hand_spec, 0.05, ("ring", 2))
    j = 6 + u.hand_spec.finger_joints.index(u.hand_spec.fingers["index"][-1])
    assert torch.equal(policy(None, u), index.expand(3, -1))  # t = 0: the window, no trigger
    u.elapsed_steps += 1
    u.command[1, j] = 0.95  # env 1's index has reached theta
    a = policy(None, u)
    assert torch.equal(a[0], index) and torch.equal(a[1], (index + ring).clamp(-1, 1))
    u.elapsed_steps += 1  # t = 2: the window has closed; env 1's trigger stays latched below theta
    u.command[1, j] = 0.5
    a = policy(None, u)
    assert torch.equal(a[0], torch.zeros_like(index)) and torch.equal(a[1], ring)
    u.elapsed_steps[1] = 0  # env 1 starts a new episode: its trigger clears
    a = policy(None, u)
    assert torch.equal(a[1], index) and torch.equal(a[2], torch.zeros_like(index))


def test_a_base_term_moves_the_fingers_first_joint_alone():
    """``finger:base:rate``: the closing direction leaves the first joints still (finger:4 and finger:3 act alike
    there); a base term moves that joint alone, rate rad per step along its axis, either way."""
    u = _env(1)
    spec = u.hand_spec
    assert parse_sequence("thumb:base:0.01:0:5")[0].base
    policy = make_sequence_policy("thumb:base:0.01:0:5+index:base:-0.01:0:5")
    a = policy(None, u)[0]
    scales = torch.as_tensor(spec.action_scales(), dtype=torch.float32)
    thumb0 = 6 + spec.finger_joints.index(spec.fingers["thumb"][0])
    index0 = 6 + spec.finger_joints.index(spec.fingers["index"][0])
    assert a[thumb0] == pytest.approx(0.01 / float(scales[thumb0]))
    assert a[index0] == pytest.approx(-0.01 / float(scales[index0]))
    assert int((a != 0).sum()) == 2
    whole, distal = finger_sweep_action(spec, 0.01, ("thumb", 4)), finger_sweep_action(spec, 0.01, ("thumb", 3))
    assert torch.equal(whole, distal) and whole[thumb0] == 0  # why base exists
    with pytest.raises(ValueError, match="k \\(or base\\)"):
        parse_sequence("thumb:bass:0.01:0:5")


def test_eval_cli_runs_a_sequence_as_run_protocol_does(tmp_path):
    """``unicross eval --policy seq:SPEC`` (worker processes resolve the spec) gives the trials of the
    sequence policy run in-process, as docs/runs/translate_zm_reference/finger_sequences.py runs it."""
    import json

    from unicross import evaluation as E
    from unicross.cli import main
    from unicross.objects import get_object_set
    spec = "index:2:0.05:0:1000+ring:2:0.05:@index:0.9"
    out = tmp_path / "e.json"
    assert main(["eval", "--policy", f"seq:{spec}", "--protocol", "translate", "--axis", "z-", "--objects", "test",
                 "--limit", "1", "--trials-per-object", "1", "--out", str(out)]) == 0
    d = json.loads(out.read_text())
    assert d["policy"] == dict(kind="sequence", sequence=spec)
    trials = E.run_protocol("translate", make_sequence_policy(spec), get_object_set("test", limit=1),
                            trials_per_object=1, seed=0, axes=["z-"], progress=False)
    assert d["trials"]["translate"] == json.loads(json.dumps(trials))


def test_eval_cli_refuses_a_bad_sequence_before_simulation(tmp_path, capsys):
    from unicross.cli import main
    assert main(["eval", "--policy", "seq:pinky:2:0.05:0:10", "--protocol", "translate", "--axis", "z-",
                 "--out", str(tmp_path / "e.json")]) == 2
    assert "no finger 'pinky'" in capsys.readouterr().err
    assert not (tmp_path / "e.json").exists()


def test_report_names_what_a_clone_copied():
    from unicross.report import how_trained
    assert how_trained({"clone_of": "seq:index:2:0.05:0:10", "config": {}}).startswith("DAgger clone of seq:index:2:")
    assert how_trained({"clone_of": "allegro/rotate_y-", "config": {}}).startswith("DAgger clone of gait:allegro/rotate_y-")


def test_a_switched_sequence_runs_each_envs_branch_by_its_objects_width():
    from unicross.objects import ObjectSpec
    u = _env()
    u.env_objects = [ObjectSpec(name=f"s{i}", shape="box", category="elongated", dims=(0.7, w, 0.06))
                     for i, w in enumerate((0.045, 0.055, 0.0489))]
    policy = make_sequence_policy("width<0.049?index:2:0.05:0:10|ring:2:0.05:0:10")
    index = finger_sweep_action(u.hand_spec, 0.05, ("index", 2))
    ring = finger_sweep_action(u.hand_spec, 0.05, ("ring", 2))
    a = policy(None, u)
    assert torch.equal(a[0], index) and torch.equal(a[1], ring) and torch.equal(a[2], index)
    u.env_objects = list(reversed(u.env_objects))  # a rebuilt scene: the mask follows its objects
    a = policy(None, u)
    assert torch.equal(a[0], index) and torch.equal(a[1], ring) and torch.equal(a[2], index)


@pytest.mark.parametrize("spec, msg", [("width<0.049?index:2:0.05:0:10", "width<W"),
                                       ("width<thin?index:2:0.05:0:10|ring:2:0.05:0:10", "must be a number"),
                                       ("width<0.049?index:2:0.05:0:10|ring:two:0.05:0:10", "integers")])
def test_malformed_switched_sequences_are_refused(spec, msg):
    with pytest.raises(ValueError, match=msg):
        parse_sequence(spec)
