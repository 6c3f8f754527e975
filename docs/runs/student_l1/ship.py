"""Ship the named seed of a judged screen of this folder (rule.txt G2 / H2 / I3) as allegro/student: copy its
committed export, then rewrite the sidecar (the replaced record under ``replaced``; the other two seeds under
``other_seeds``).

    python docs/runs/student_l1/ship.py SCREEN [--dry]

SCREEN is a key of ``SCREENS`` (G: x+ weight 10, seeds 1-3; H: x+ weight 15, seeds 1-3; I: G's recipe on seeds 4-6,
rotate cells over evaluation seeds 0-3; J: I's judge, x+ weight 5, seeds 7-9; K: J's recipe on seeds 10-12, long-horizon cells over evaluation seeds 0-3 too; all x+ walked three times, l1 0.01, from the shipped student;
L: K's with env.chain_repeats={rotate_x+: 1, translate_z-: 3} on seeds 13-15, from K's initial student, tag _chz; M: K's
stage from K's initial student with the experts shipped at 723f266 (new z- and y+), seeds 16-18, tag _m; O: M's runs
resumed to epoch 2000 with the grasp rows weighted 3, tag _o: ``RESUMED``; P: O's runs resumed to epoch 2500 with the
z+ expert of 564f969, tag _p: ``CONTINUED``, its record appended to the shipped one's; Q: P's on DAgger seeds 116-118,
tag _q, ``CONTINUED``). It refuses to
write unless the screen's judge output (``judge_<screen>.txt``, e.g. judge_h.txt) ends in PASSED; ``--dry`` prints the new sidecar without writing anything. The stage command in the sidecar is
common.sh's ``stage`` with ``ship_screen``'s arguments, as run_g.sh / run_h.sh call it.
"""
import json
import shutil
import sys

import torch

D = "docs/runs/student_l1"
CK = "unicross/checkpoints/allegro/student"
# the x+ weight (the run, export and cells names follow it: common.sh ship_screen), the seeds (the first ships) and
# the judge's command
JUDGE3 = "python docs/runs/student_xp_drift/judge3.py {cells}"
SCREENS = {"G": (10, (1, 2, 3), JUDGE3), "H": (15, (1, 2, 3), JUDGE3),
           "I": (10, (4, 5, 6), f"python {D}/judge_i.py   # also reads {D}/rotate_seeds_*.json"),
           "J": (5, (7, 8, 9), f"python {D}/judge_i.py J   # also reads {D}/rotate_seeds_*.json"),
           "K": (5, (10, 11, 12), f"python {D}/judge_i.py K   # also reads {D}/rotate_seeds_*.json, {D}/chain_seeds_*.json"),
           "L": (5, (13, 14, 15), f"python {D}/judge_i.py L   # also reads {D}/rotate_seeds_*.json, {D}/chain_seeds_*.json"),
           "M": (5, (16, 17, 18), f"python {D}/judge_i.py M   # also reads {D}/rotate_seeds_*.json, {D}/chain_seeds_*.json"),
           "O": (5, (16, 17, 18), f"python {D}/judge_i.py O   # also reads {D}/rotate_seeds_*.json, {D}/chain_seeds_*.json"),
           "P": (5, (16, 17, 18), f"python {D}/judge_i.py P   # also reads {D}/rotate_seeds_*.json, {D}/chain_seeds_*.json"),
           "Q": (5, (16, 17, 18), f"python {D}/judge_i.py Q   # also reads {D}/rotate_seeds_*.json, {D}/chain_seeds_*.json")}
# screens that resume another screen's runs (run_o.sh): the screen whose stage they resume, their tag, the epochs they
# run to and the resume's arguments
RESUMED = {"O": ("M", "_o", 2000, "--set 'optim.mode_weights={rotate_x+: 5, grasp: 3}'")}
# screens whose export tag and stage differ from ship_screen's (run_l.sh): the tag, the stage's last arguments and
# the command that makes their initial student, which is the shipped student's own initial one (its ``replaced``)
OTHER_STAGE = {"L": ("_chz", "--set model.init_policy=runs/student_pre_k.pt "
                             "--set 'env.chain_repeats={{rotate_x+: 1, translate_z-: 3}}'",
                     "git show 06e213f^:unicross/checkpoints/allegro/student.pt > runs/student_pre_k.pt   "
                     "# K's initial student (run_l.sh)"),
               "M": ("_m", "--set model.init_policy=runs/student_pre_k.pt",
                     "git show 06e213f^:unicross/checkpoints/allegro/student.pt > runs/student_pre_k.pt   "
                     "# K's initial student (run_m.sh)")}
# the teachers: the experts folder, the commit whose shipped experts fill it and their description
TEACHERS = ("runs/experts1205x", "fe6c582", "the ten Allegro experts shipped at commit fe6c582 (rotate x+ = the clone "
            "of the x+ finger sequence)")
OTHER_TEACHERS = {"M": ("runs/experts1207", "723f266", "the ten Allegro experts shipped at commit 723f266 (rotate x+ = "
                        "the clone of the x+ finger sequence; z- and y+ = the clones of gaits searched under 12 solver "
                        "iterations, 63rd and 64th sessions)")}
# screens that resume the shipped student's own run with other teachers (run_p.sh): the screen shipped, its tag, the
# new screen's tag, the epochs, the experts folder, how it is made, the teachers' description and the resume's arguments
# (a template of the seed {s}: braces doubled)
# P and Q (common.sh resume_o) share the experts folder, how it is made and the teachers; Q adds the DAgger seed
EXPERTS_1207P = ("runs/experts1207p",
                 "for m in {modes}; do mkdir -p runs/experts1207p/$m; git show 723f266:unicross/checkpoints/allegro/"
                 "$m.pt > runs/experts1207p/$m/checkpoint.pt; done; git show 564f969:unicross/checkpoints/allegro/"
                 "rotate_z+.pt > runs/experts1207p/rotate_z+/checkpoint.pt   # {D}/run_{screen}.sh",
                 "the ten Allegro experts shipped at commit 564f969 (those of 723f266 but rotate z+, the clone of a "
                 "z+ gait searched under 12 solver iterations, 68th session)")
O_RESUME = "--set 'optim.mode_weights={{rotate_x+: 5, grasp: 3}}'"
CONTINUED = {"P": ("O", "_o", "_p", 2500, *EXPERTS_1207P, O_RESUME),
             "Q": ("O", "_o", "_q", 2500, *EXPERTS_1207P, O_RESUME + " --set seed=1{s}")}
MODES = "grasp relocate rotate_x+ rotate_x- rotate_y+ rotate_y- rotate_z+ rotate_z- translate_z+ translate_z-"



def continued_record(name, old, ship_seed, others, judge_cmd):
    """The sidecar of a ``CONTINUED`` screen: the shipped student's record (``old``, the screen it was shipped by)
    with this screen's resume of the same run appended; frames and minutes add the resume's alone."""
    shipped_by, old_tag, tag, epochs, experts, make_experts, teachers, resume_args = CONTINUED[name]
    if not old.get("rule", "").startswith(f"{D}/rule.txt screen {shipped_by} "):
        sys.exit(f"screen {name} continues screen {shipped_by}'s student, but the shipped one is of: {old.get('rule')}")
    run, prev = f"runs/l1rep3{tag.strip('_')}_s{{s}}", f"runs/l1rep3{old_tag.strip('_')}_s{{s}}"
    export, prev_export = f"{D}/student_l1_rep3{tag}_s{{s}}", f"{D}/student_l1_rep3{old_tag}_s{{s}}"
    cells_of = f"{D}/student_cells_rep3{tag}_s{{s}}.json"
    ck = torch.load(f"{export.format(s=ship_seed)}.pt", map_location="cpu", weights_only=False)
    was = json.load(open(f"{prev_export.format(s=ship_seed)}.json"))
    wall_s = json.load(open(f"{export.format(s=ship_seed)}.json"))["train_wall_s"] - was["train_wall_s"]
    frames = ck["frames"] - was["frames"]
    resume = f"unicross distill --resume --experts {experts} --out {run} --epochs {epochs} {resume_args}"
    commands = old["commands"] + [
        make_experts.format(modes=MODES, D=D, screen=name.lower()),
        f"cp -r {prev.format(s=ship_seed)} {run.format(s=ship_seed)}   # {D}/run_{name.lower()}.sh",
        resume.format(s=ship_seed) + f"   # commit {ck['git_commit'][:7]}, {wall_s / 60:.0f} min on 2 cores (rule.txt "
        f"screen {name}: the shipped student's run resumed with its replay buffer, labelled again by the new teachers)",
        f"unicross export {run.format(s=ship_seed)} --out {export.format(s=ship_seed)}.pt",
        f"python docs/runs/student_ft_1202b/seed_cells.py {export.format(s=ship_seed)}.pt "
        f"{cells_of.format(s=ship_seed)}   # the report's test cells and long horizon, 7 min",
        judge_cmd + f"   # rule.txt screen {name}",
        f"cp {export.format(s=ship_seed)}.pt {CK}.pt   # python {D}/ship.py {name} (this sidecar)",
    ]
    cells = json.load(open(cells_of.format(s=ship_seed)))
    seeds = []
    for s in others:
        c = json.load(open(cells_of.format(s=s)))
        seeds.append(dict(seed=s, command=f"cp -r {prev.format(s=s)} {run.format(s=s)}; {resume.format(s=s)} (export "
                          f"{export.format(s=s)}.pt); judged pooled with seed {ship_seed}, not chosen on",
                          test_cells=test_cells(c), long_horizon_overall=overall(c)))
    return dict(
        skill=ck["skill"], axis=ck["axis"], hand=ck["hand"], epoch=ck["epoch"], frames=old["frames"] + frames,
        distilled_modes=ck["distilled_modes"], git_commit=ck["git_commit"], commits=old["commits"] + [ck["git_commit"]],
        commands=commands, hardware=old["hardware"], train_wall_s=round(old["train_wall_s"] + wall_s, 1),
        stage_frames=frames, stage_wall_s=round(wall_s, 1),
        frames_note=f"frames and train_wall_s count every stage from the first DAgger run: the student this resume "
                    f"continued ({old['frames']} frames, {old['train_wall_s']} s; its own frames_note under replaced) "
                    f"and this resume (stage_frames, stage_wall_s: to epoch {epochs} with {resume_args.format(s=ship_seed)}, on the ten "
                    f"experts of {experts})",
        rule=f"{D}/rule.txt screen {name} (three seeds pooled, {judge_cmd.split()[1]}; seed {ship_seed} named "
             "before the runs)",
        teachers=teachers, test_cells=test_cells(cells), long_horizon_overall=overall(cells), other_seeds=seeds,
        long_horizon_note=old["long_horizon_note"], replaced=old)


def test_cells(c):
    return {m: v["cell"] for m, v in c["test"].items()}


def overall(c):
    return {k: v["overall"]["sr"] for k, v in c["long_horizon"]["summary"].items()}


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--dry"]
    dry = "--dry" in sys.argv
    if len(args) != 1 or args[0] not in SCREENS:
        sys.exit(f"usage: python {D}/ship.py SCREEN [--dry], SCREEN one of {', '.join(SCREENS)}")
    name = args[0]
    weight, (ship_seed, *others), judge_cmd = SCREENS[name]
    staged, tag, epochs, resume_args = RESUMED.get(name, (name, None, None, None))
    stage_tag, extra, init_cmd = OTHER_STAGE.get(staged, (f"_w{weight}ship", "--set model.init_policy=allegro/student",
                                                          None))
    tag = tag or stage_tag
    experts, experts_commit, teachers = OTHER_TEACHERS.get(staged, TEACHERS)
    stage_run = f"runs/l1rep3{stage_tag.strip('_')}_s{{s}}"
    run = f"runs/l1rep3{tag.strip('_')}_s{{s}}"
    export = f"{D}/student_l1_rep3{tag}_s{{s}}"
    cells_of = f"{D}/student_cells_rep3{tag}_s{{s}}.json"

    judge = f"{D}/judge_{name.lower()}.txt"
    try:
        verdict = open(judge).read().split()[-1]
    except FileNotFoundError:
        verdict = "missing"
    if verdict != "PASSED" and not dry:
        sys.exit(f"{judge}: {verdict}; screen {name} does not ship (rule.txt screen {name})")
    old = json.load(open(f"{CK}.json"))
    if old.get("rule", "").startswith(f"{D}/rule.txt screen {name} "):  # run again after shipping: keep the record
        old = old["replaced"]                                              # it replaced
    if name in CONTINUED:  # the shipped student's own run resumed (run_p.sh)
        new = continued_record(name, old, ship_seed, others, judge_cmd)
        export = f"{D}/student_l1_rep3{CONTINUED[name][2]}_s{{s}}"
    else:
        base = old["replaced"] if init_cmd else old  # the initial student's record: the lineage's commands and frames
        ck = torch.load(f"{export.format(s=ship_seed)}.pt", map_location="cpu", weights_only=False)
        wall_s = json.load(open(f"{export.format(s=ship_seed)}.json"))["train_wall_s"]  # the stage's, from the export's sidecar
        # the commit and minutes of the stage's first run (a resumed screen: the resumed export's record)
        first = json.load(open(f"{D}/student_l1_rep3{stage_tag}_s{ship_seed}.json")) if resume_args else dict(
            git_commit=ck["git_commit"], train_wall_s=wall_s)
        stage = (f"unicross distill --experts {experts} --out " + stage_run + " --epochs 1500 "
                 "--set model.init_policy=runs/student_1204_morning.pt --set optim.lr=1.0e-4 "
                 "--set optim.warmup_frames=102400 --set env.object_limit=null --set collector.rollout_steps=256 "
                 "--set optim.grad_steps=30 --set optim.batch_size=1024 --set buffer.capacity=300000 "
                 "--set logging.checkpoint_every=25 --set seed={s} --set env.chain_share=0.15 "
                 "--set 'optim.mode_weights={{rotate_x+: 30}}' --set optim.l1=0.01 "
                 "--set 'env.mode_repeats={{rotate_x+: 3}}' "
                 f"--set 'optim.mode_weights={{{{rotate_x+: {weight}}}}}' " + extra)
        resume = (f"unicross distill --resume --out {run} --epochs {epochs} "  # a template of {s}, as stage
                  + resume_args.replace("{", "{{").replace("}", "}}")) if resume_args else None
        commands = base["commands"] + ([init_cmd] if init_cmd else []) + [
            f"for m in {MODES}; do mkdir -p {experts}/$m; git show {experts_commit}:unicross/checkpoints/allegro/$m.pt "
            f"> {experts}/$m/checkpoint.pt; done   # {teachers}; {D}/common.sh: experts_at",
            stage.format(s=ship_seed) + f"   # commit {first['git_commit'][:7]}, {first['train_wall_s'] / 60:.0f} min on 2 cores ({D}/rule.txt "
            f"screen {staged}; later --set values override earlier ones: init = "
            f"{'runs/student_pre_k.pt, the initial student of the one this replaces' if init_cmd else 'the student this replaces'}, "
            f"x+ weight {weight})",
            *([f"cp -r {stage_run.format(s=ship_seed)} {run.format(s=ship_seed)}   # {D}/run_{name.lower()}.sh",
               resume.format(s=ship_seed) + f"   # commit {ck['git_commit'][:7]}, {(wall_s - first['train_wall_s']) / 60:.0f} "
               f"min on 2 cores (rule.txt screen {name}: the stage resumed with its replay buffer)"]
              if resume_args else []),
            f"unicross export {run.format(s=ship_seed)} --out {export.format(s=ship_seed)}.pt",
            f"python docs/runs/student_ft_1202b/seed_cells.py {export.format(s=ship_seed)}.pt "
            f"{cells_of.format(s=ship_seed)}   # the report's test cells and long horizon, 7 min",
            judge_cmd.format(cells=" ".join(cells_of.format(s=s) for s in (ship_seed, *others)))
            + f"   # rule.txt screen {name}",
            f"cp {export.format(s=ship_seed)}.pt {CK}.pt   # python {D}/ship.py {name} (this sidecar)",
        ]

        cells = json.load(open(cells_of.format(s=ship_seed)))
        seeds = []
        for s in others:
            c = json.load(open(cells_of.format(s=s)))
            seeds.append(dict(seed=s, command=stage.format(s=s) + (f"; {resume.format(s=s)}" if resume else "") + f" (export {export.format(s=s)}.pt); judged pooled "
                              f"with seed {ship_seed}, not chosen on", test_cells=test_cells(c), long_horizon_overall=overall(c)))
        new = dict(
            skill=ck["skill"], axis=ck["axis"], hand=ck["hand"], epoch=ck["epoch"], frames=base["frames"] + ck["frames"],
            distilled_modes=ck["distilled_modes"], git_commit=ck["git_commit"],
            commits=base["commits"] + [first["git_commit"]] * bool(resume_args) + [ck["git_commit"]], commands=commands, hardware=base["hardware"],
            train_wall_s=round(base["train_wall_s"] + wall_s, 1), stage_frames=ck["frames"], stage_wall_s=round(wall_s, 1),
            frames_note="frames and train_wall_s count every stage from the first DAgger run: the student this stage "
                        f"started from ({base['frames']} frames, {base['train_wall_s']} s; its own frames_note under "
                        f"replaced{'.replaced' if init_cmd else ''}) and this "
                        f"stage (stage_frames, stage_wall_s: rotate x+ walked three times with weight {weight}, l1 0.01, "
                        f"{f'resumed to epoch {epochs} with {resume_args}, ' if resume_args else ''}"
                        f"env.chain_share 0.15{' (chain_repeats: the stage command)' if 'chain_repeats' in extra else ''}, on the ten "
                        f"experts of {experts_commit})",
            rule=f"{D}/rule.txt screen {name} (three seeds pooled, {judge_cmd.split()[1]}; seed {ship_seed} named "
                 "before the runs)",
            teachers=teachers,
            test_cells=test_cells(cells), long_horizon_overall=overall(cells), other_seeds=seeds,
            long_horizon_note="the stage acts in long-horizon chains too (env.chain_share 0.15); per seed and pooled in "
                              f"{D}/README.md",
            replaced=old,
        )
    if dry:
        print(json.dumps({k: v for k, v in new.items() if k not in ("replaced", "commands")}, indent=1))
        print("\n".join(["commands (the last seven):"] + new["commands"][-7:]))
    else:
        shutil.copyfile(f"{export.format(s=ship_seed)}.pt", f"{CK}.pt")
        json.dump(new, open(f"{CK}.json", "w"), indent=1)
        print(f"wrote {CK}.pt and {CK}.json")
