"""``unicross report --paper`` end to end on one object per group and one trial per protocol."""
import pytest

from unicross.cli import main


def test_report_paper_one_trial(tmp_path):
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    from unicross.report import _cell, shipped
    out = tmp_path / "results.md"
    assert main(["report", "--paper", "--limit", "1", "--trials-per-object", "1", "--min-trials", "0",
                 "--out", str(out)]) == 0
    text = out.read_text()
    assert text.splitlines()[2].startswith("Command: `unicross report") and "--min-trials 0" in text.splitlines()[2]
    assert text.splitlines()[6].startswith("Machine: ") and "step math " in text.splitlines()[6]
    for title in ("Experts, held-out test objects", "Student, held-out test objects", "Unseen objects",
                  "Disturbances", "Baselines", "Training budget of the shipped checkpoints", "Long horizon"):
        assert f"## {title}" in text
    assert "In-hand phase by mode: " in text
    if all(m in shipped("allegro") for m in E.F.MODES) and "student" in shipped("allegro"):  # the teachers' long horizon on the same trials
        lh = text.split("## Long horizon", 1)[1]
        assert "`unicross chain --policy experts:allegro`" in lh
        trials = E.run_chain(E.make_experts_policy("allegro", "allegro")[0], get_object_set("test", limit=1),
                             trials_per_object=1, seed=0, progress=False)
        experts_part = lh.split("experts:allegro", 1)[1]
        assert E.chain_table(E.summarize_chain(trials)) in experts_part
        # the report keeps the summaries of its long horizons (seed_cells.py reads them)
        from unicross.report import PaperReport
        rep = PaperReport(hand="allegro", limit=1, trials=1, min_trials=0)
        lines = rep.chain("experts", E.make_experts_policy("allegro", "allegro")[0])
        kept = rep.chain_summaries["experts"]
        assert lines[0] == E.chain_table(kept["summary"]) == E.chain_table(E.summarize_chain(trials))
        assert kept["in_hand_phase_by_mode"] == E.chain_last_phase_by_mode(trials)
    n_test = len(get_object_set("test", limit=1))
    ships = shipped("allegro")
    for mode in ("grasp", "relocate"):
        if mode in ships:  # one trial per test object
            assert f"| {mode} | allegro/{mode} | " in text and f"(n={n_test})" in text
    from unicross.gaits import make_gait_policy, shipped_gaits
    gaits = shipped_gaits("allegro")
    for mode in ("rotate_x+", "translate_z-"):
        if mode not in ships:
            extra = " (a scripted gait: see below)" if mode in gaits else ""
            assert f"| {mode} | expert not shipped{extra} | -- |" in text
    if gaits:  # each shipped gait has its row, and a row is the evaluation of that gait
        assert "## Scripted finger gaits (not PPO experts), held-out test objects" in text
        assert all(f"| {mode} | gait:{spec} | " in text for mode, spec in gaits.items())
        mode = next(iter(gaits))
        trials = E.run_protocol("rotate", make_gait_policy(gaits[mode]), get_object_set("test", limit=1),
                                trials_per_object=1, seed=0, progress=False, axes=[mode.split("_")[1]])
        assert f"| {mode} | gait:{gaits[mode]} | {_cell(E.summarize('rotate', trials), 'rotate')} |" in text
    # each physical reference has its row on test and unseen objects, and a row is its evaluation
    assert "## Physical references (scripted, not policies), held-out test objects" in text
    assert "## Physical references (scripted, not policies), unseen objects" in text
    trials = E.run_protocol("translate", E.make_reference_policy(), get_object_set("test", limit=1),
                            trials_per_object=1, seed=0, progress=False, axes=["z-"])
    row = (f"| translate_z- | reference (pull: the index finger's 2 distal joints at +0.05 rad per step) | "
           f"{_cell(E.summarize('translate', trials), 'translate')} |")
    assert row in text
    assert "| translate_z+ | reference (open: every finger joint at -0.02 rad per step) | " in text
    # a cell is the evaluation itself: the zero-action relocation row equals an independent run
    trials = E.run_protocol("relocate", E.zero_policy, get_object_set("test", limit=1), trials_per_object=1,
                            seed=0, progress=False)
    assert f"| relocate | zero | {_cell(E.summarize('relocate', trials), 'relocate')} |" in text
    for mode in ("rotate_x+", "rotate_z-", "translate_z+", "translate_z-"):  # the bar of each in-hand expert
        assert f"| {mode} | zero | " in text
    if "student" in ships:  # the paper's unseen and disturbance rows are its student's: ours has them too
        for title in ("## Unseen objects", "## Disturbances"):
            section = text.split(title, 1)[1].split("\n## ", 1)[0]
            assert "| grasp | allegro/grasp | " in section and "| grasp | allegro/student | " in section
        objs, _ = E.protocol_objects("grasp", get_object_set("unseen", limit=1), "allegro")
        trials = E.run_protocol_workers("grasp", "allegro/student", objs, trials_per_object=1, seed=0, progress=False)
        assert f"| grasp | allegro/student | {_cell(E.summarize('grasp', trials), 'grasp')} |" in text.split("## Unseen", 1)[1].split("\n## ", 1)[0]
    n_rot = sum(m.startswith("rotate") for m in ships)
    if n_rot:  # the issue's rotate target is read off one pooled line under the experts' table
        assert f"Rotate, pooled over the {n_rot} axes with an expert (of 6): " in text


def test_machine_line_names_the_step_math_mode(monkeypatch):
    """The header line that a cell's reproduction needs follows the ``UNICROSS_COMPILE`` switch."""
    from unicross.report import machine_line
    monkeypatch.setenv("UNICROSS_COMPILE", "0")
    assert "step math eager (`UNICROSS_COMPILE=0`)" in machine_line()
    monkeypatch.setenv("UNICROSS_COMPILE", "1")
    assert "step math compiled (`UNICROSS_COMPILE=1`)" in machine_line()
    monkeypatch.setenv("UNICROSS_COMPILE", "torch")
    assert "step math torch.compile" in machine_line()


def test_report_raises_trials_to_the_minimum():
    """A cell over few objects gets more trials per object, never fewer than asked."""
    from unicross.report import PaperReport
    r = PaperReport(trials=3, min_trials=100)
    assert [r.trials_per_object(n) for n in (40, 34, 20, 10, 7, 200)] == [3, 3, 5, 10, 15, 3]
    assert all(n * r.trials_per_object(n) >= 100 for n in range(1, 120))
    assert PaperReport(trials=2, min_trials=0).trials_per_object(5) == 2


@pytest.mark.parametrize("argv,msg", [
    (["report", "--paper", "--trials-per-object", "0"], ">= 1"),
    (["report", "--paper", "--min-trials", "-1"], ">= 0"),
    (["report", "--paper", "some.json"], "takes no eval JSON files"),
    (["report"], "--paper"),
    (["report", "--paper", "--sim", "solver_iterations=12"], "KEY one of"),
])
def test_report_bad_input_fails_before_simulation(argv, msg, capsys):
    assert main(argv) == 2
    assert msg in capsys.readouterr().err


def test_report_out_directory_refused(tmp_path, capsys):
    assert main(["report", "--paper", "--out", str(tmp_path)]) == 2
    assert "is a directory" in capsys.readouterr().err


def test_report_sim_reaches_every_cell_and_chain_and_is_printed(tmp_path, monkeypatch):
    """``report --paper --sim KEY=VALUE`` runs every cell and both long horizons under that physics
    (overriding each policy's own) and prints it in the command and the header."""
    from unicross import evaluation as E
    from unicross import report as Rp
    seen = []
    monkeypatch.setattr(E, "run_protocol_workers", lambda *a, **kw: seen.append(("cell", kw.get("sim"))) or [])
    monkeypatch.setattr(E, "run_chain", lambda *a, **kw: seen.append(("chain", kw.get("sim"))) or [])
    monkeypatch.setattr(E, "summarize", lambda *a, **kw: dict(successes=0, n=1))
    monkeypatch.setattr(E, "summarize_chain", lambda *a, **kw: {})
    monkeypatch.setattr(E, "chain_table", lambda *a, **kw: "")
    monkeypatch.setattr(E, "chain_last_phase_by_mode", lambda *a, **kw: {})
    monkeypatch.setattr(Rp, "_cell", lambda *a, **kw: "--")
    out = tmp_path / "r.md"
    assert main(["report", "--paper", "--limit", "1", "--sim", "solver_position_iterations=8", "--out", str(out)]) == 0
    text = out.read_text()
    assert "--sim solver_position_iterations=8 --out" in text
    assert "Physics: configs/task.yaml's sim section with solver_position_iterations=8 in every cell." in text
    kinds = {k for k, _ in seen}
    assert kinds == {"cell", "chain"} and all(sim == dict(solver_position_iterations=8) for _, sim in seen)


def test_report_long_horizon_runs_a_policy_under_its_own_physics_unless_sim_is_given(monkeypatch):
    """Without ``--sim`` the report's long horizon runs a policy made under other physics under its own, as
    its cells do (``run_protocol_workers``); with ``--sim`` under that."""
    from unicross import evaluation as E
    from unicross.report import PaperReport
    seen = []
    monkeypatch.setattr(E, "run_chain", lambda *a, **kw: seen.append(kw.get("sim")) or [])
    monkeypatch.setattr(E, "summarize_chain", lambda *a, **kw: {})
    monkeypatch.setattr(E, "chain_table", lambda *a, **kw: "")
    monkeypatch.setattr(E, "chain_last_phase_by_mode", lambda *a, **kw: {})
    own = dict(sim=dict(solver_position_iterations=8))
    PaperReport(limit=1).chain("x", E.zero_policy, own)
    PaperReport(limit=1).chain("x", E.zero_policy)
    PaperReport(limit=1, sim=dict(solver_position_iterations=16)).chain("x", E.zero_policy, own)
    assert seen == [dict(solver_position_iterations=8), None, dict(solver_position_iterations=16)]


def test_paper_values_format():
    from unicross.report import _paper
    assert _paper("Ours", "relocate") == "99.0 / 0.54 / 0.0134"
    assert _paper("Experts", "grasp") == "99.0"


def test_paper_column_of_another_hand_is_its_row_of_the_hands_table():
    """For MANO and Sharpa Wave the experts' and the student's tables show the paper's row of that hand
    (its hands table), and the settings the paper reports for Allegro only show "--"; a hand the paper
    does not have gets "--" everywhere."""
    from unicross.report import _paper
    assert _paper("Ours", "relocate", "mano") == "96.6 / 1.26 / 0.0207"
    assert _paper("Experts", "grasp", "sharpa_wave") == "99.1"
    assert _paper("Ours", "translate", "sharpa_wave") == "99.0 / 17.8"
    assert _paper("Uns.", "grasp", "mano") == "--" and _paper("Dis.", "relocate", "sharpa_wave") == "--"
    assert _paper("Ours", "grasp", "inspire") == "--"
    assert _paper("Uns.", "grasp", "allegro") == "95.8"


def test_a_checkpoint_on_top_of_a_gait_is_named_so_in_the_tables(tmp_path):
    import torch
    from unicross.report import policy_label
    from unicross.rl.policy_io import read_torch_file, resolve_checkpoint
    assert policy_label("allegro/grasp") == "allegro/grasp"
    ck = read_torch_file(resolve_checkpoint("allegro/rotate_y-"), "checkpoint")
    clone_of = ck.pop("clone_of")
    torch.save(ck, tmp_path / "plain.pt")
    assert policy_label(str(tmp_path / "plain.pt")) == str(tmp_path / "plain.pt")
    ck["config"] = dict(ck["config"], model=dict(ck["config"]["model"], base_policy="allegro/rotate_y-"))
    torch.save(ck, tmp_path / "r.pt")
    assert policy_label(str(tmp_path / "r.pt")) == f"{tmp_path / 'r.pt'} (PPO on top of gait:allegro/rotate_y-)"
    # a network cloned from a gait (benchmarks/gait_clone.py records its gait) is not called a PPO expert
    # (since 2026-12-01 the shipped y- clone is of the gait run without its stop: its label says so)
    assert clone_of == "allegro/rotate_y-,stop=0"
    assert policy_label("allegro/rotate_y-") == f"allegro/rotate_y- (DAgger clone of gait:{clone_of}, not PPO)"
    # PPO started from such a clone (the trainer records model.init_policy's clone_of as started_from)
    ck.pop("config")
    ck["started_from"] = dict(policy="runs/clone/policy.pt", clone_of=clone_of)
    torch.save(ck, tmp_path / "ft.pt")
    assert policy_label(str(tmp_path / "ft.pt")) == f"{tmp_path / 'ft.pt'} (PPO from a DAgger clone of gait:{clone_of})"


def test_training_budget_reads_every_shipped_sidecar():
    """One row per shipped checkpoint with the frames and wall-clock its sidecar records, and how it
    was made read from the checkpoint (a clone or the student is not called PPO)."""
    import json
    from unicross.report import CHECKPOINTS, PAPER_FRAMES_PER_EXPERT, how_trained, shipped, training_budget
    lines = training_budget("allegro")
    rows = [r for r in lines if r.startswith("| allegro/")]
    assert len(rows) == len(shipped("allegro"))
    for name, spec in shipped("allegro").items():
        side = json.loads((CHECKPOINTS / "allegro" / f"{name}.json").read_text())
        row = next(r for r in rows if r.startswith(f"| {spec} |"))
        if side.get("frames"):
            assert f"| {side['frames']:,} |" in row
            if name != "student":
                assert row.endswith(f"| {side['frames'] / PAPER_FRAMES_PER_EXPERT:.1e} |")
        if side.get("train_wall_s"):
            assert f"| {side['train_wall_s'] / 60:.0f} min |" in row
    assert how_trained({"distilled_modes": ["grasp", "relocate"]}) == "DAgger student of 2 experts"
    assert how_trained({"clone_of": "allegro/rotate_y-"}).startswith("DAgger clone of gait:allegro/rotate_y-")
    assert how_trained({"started_from": {"policy": "p.pt", "clone_of": "allegro/rotate_y-"}}).startswith(
        "PPO from a DAgger clone of gait:allegro/rotate_y-")
    assert how_trained({"started_from": {"policy": "p.pt", "clone_of": None}, "config": {"model": {}}}) == "PPO"
    assert how_trained({"config": {"model": {"init_reference": 0.75}}}).startswith("PPO from a scripted start")
    assert how_trained({"config": {"model": {}}}) == "PPO"
