"""``unicross report --paper``: the paper's evaluation tables regenerated from the shipped checkpoints.

Every cell is an evaluation run by this module (no number is copied from elsewhere) with its n and
95% Wilson interval, and the paper's value beside it. Modes without a shipped expert, or a table
that needs the student when none is shipped, are listed as not shipped rather than left out. The
command that regenerates the file is printed at its top.
"""
from __future__ import annotations

import math
import os
import platform
import shlex
import time
from pathlib import Path
from typing import Callable, Dict, List, Optional

import torch

from unicross import evaluation as E
from unicross import formulation as F
from unicross.compiling import compile_enabled, compile_with_dynamo
from unicross.objects import get_object_set
from unicross.registry import mode_axis, skill_of_mode

CHECKPOINTS = Path(__file__).parent / "checkpoints"

# The paper's values (Tables "Comparison", "Generalization & Robustness", "Ablation", "Long-horizon"):
# per skill (SR %, metric): relocate (SR, PE cm, AE rad), rotate (SR, Rot. rad), translate (SR, Trans. cm).
PAPER = {
    "Experts": dict(grasp=(99.0,), relocate=(99.1, 0.53, 0.0140), rotate=(99.1, 14.1), translate=(99.3, 20.5)),
    "Ours": dict(grasp=(98.7,), relocate=(99.0, 0.54, 0.0134), rotate=(98.8, 13.6), translate=(99.1, 20.3)),
    "Uns.": dict(grasp=(95.8,), relocate=(98.6, 0.50, 0.0152), rotate=(98.3, 14.5), translate=(96.0, 18.1)),
    "Dis.": dict(grasp=(98.6,), relocate=(99.0, 0.55, 0.0136), rotate=(98.4, 13.7), translate=(97.6, 20.2)),
    "Gen. (Base.)": dict(grasp=(97.1,), relocate=(92.8, 0.85, 0.0231), rotate=(62.7, 9.43), translate=(70.6, 5.81)),
    "long": {"Gr. + Re. + Rot.": (99.7, 92.2, 95.1, 87.4), "Gr. + Re. + Trans.": (99.9, 98.3, 98.0, 96.3)},
}
# The paper's other hands (Table "Generalization & Robustness": one unified policy per hand, test objects); the
# paper reports every other setting for Allegro only.
PAPER_HANDS = {
    "mano": dict(grasp=(96.8,), relocate=(96.6, 1.26, 0.0207), rotate=(94.5, 10.3), translate=(95.3, 10.3)),
    "sharpa_wave": dict(grasp=(99.1,), relocate=(98.0, 0.80, 0.0116), rotate=(98.5, 13.5), translate=(99.0, 17.8)),
}
# The budget the issue sets beside ours (HORA-style PPO on a GPU); the paper itself states no frame count.
PAPER_FRAMES_PER_EXPERT = 1.5e9


def shipped(hand: str = "allegro") -> Dict[str, str]:
    """Mode (or ``student``) -> ``<hand>/<name>`` of every checkpoint shipped for ``hand``."""
    d = CHECKPOINTS / hand
    names = list(F.MODES) + ["student"]
    return {n: f"{hand}/{n}" for n in names if (d / f"{n}.pt").exists()}


def _gait_origin(ck: dict):
    """``("residual", gait)`` for a checkpoint that acts on top of a scripted gait
    (``model.base_policy``), ``("clone", gait)`` for a network cloned from one (``clone_of``, written
    by ``benchmarks/gait_clone.py``), ``("ppo_from_clone", gait)`` for PPO started from such a clone
    (``model.init_policy``, recorded by the trainer as ``started_from``), else None."""
    from unicross.rl.policy_io import base_policy_of
    base = base_policy_of(ck)
    if base is not None:
        return "residual", base
    if ck.get("clone_of"):
        return "clone", ck["clone_of"]
    start = (ck.get("started_from") or {}).get("clone_of")
    return ("ppo_from_clone", start) if start else None


def _scripted(clone_of: str) -> str:
    """The ``--policy`` spec of what a clone copied: a finger sequence (``seq:...``) or a gait."""
    return clone_of if clone_of.startswith("seq:") else f"gait:{clone_of}"


# how a checkpoint made from a scripted motion is named, and what its training budget leaves out
_ORIGIN_NAMES = {"residual": ("PPO on top of {}", ""),
                 "clone": ("DAgger clone of {}", " (its search not counted)"),
                 "ppo_from_clone": ("PPO from a DAgger clone of {}", " (the clone's frames not counted)")}


def cpu_model() -> str:
    """The CPU's model name (``/proc/cpuinfo``; ``platform.processor()`` elsewhere)."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def machine_line() -> str:
    """The report's machine and step-math mode, which its cells need to repeat to the trial: the compiled and eager
    step math differ by ~1e-8 per step (and Inductor's and ATen's kernels by CPU instruction set), and an in-hand
    rotation can turn that into another outcome (docs/runs/student_l1/README.md, "Screen I")."""
    switch = os.environ.get("UNICROSS_COMPILE", "1")
    math_mode = "torch.compile" if compile_with_dynamo() else "compiled" if compile_enabled() else "eager"
    return (f"Machine: {cpu_model()} ({torch.backends.cpu.get_cpu_capability()} kernels), {os.cpu_count()} cores, "
            f"torch {torch.__version__}; step math {math_mode} "
            f"(`UNICROSS_COMPILE={switch}`). The cells repeat to the trial on the same CPU and step-math mode; "
            "elsewhere the step's rounding can change single trials (mostly in-hand rotations), within the cells' "
            "intervals.")


def policy_label(spec: str) -> str:
    """A checkpoint's name in the tables, saying so when it acts on top of a scripted gait or is a
    network cloned from one rather than a PPO expert, or PPO started from such a clone."""
    from unicross.rl.policy_io import read_torch_file, resolve_checkpoint
    origin = _gait_origin(read_torch_file(resolve_checkpoint(spec), "checkpoint"))
    if origin is None:
        return spec
    how, motion = origin
    return f"{spec} ({_ORIGIN_NAMES[how][0].format(_scripted(motion))}{', not PPO' if how == 'clone' else ''})"


def how_trained(ck: dict) -> str:
    """How a shipped checkpoint was made, from what it stores: a DAgger student, a network cloned
    from a scripted gait, PPO on top of a gait or from such a clone, PPO from a scripted start, or PPO."""
    if ck.get("distilled_modes"):
        return f"DAgger student of {len(ck['distilled_modes'])} experts"
    origin = _gait_origin(ck)
    if origin is not None:
        how, motion = origin
        name, uncounted = _ORIGIN_NAMES[how]
        return name.format(_scripted(motion)) + uncounted
    init = (ck.get("config") or {}).get("model", {}).get("init_reference")
    return f"PPO from a scripted start (model.init_reference {init:g})" if init else "PPO"


def training_budget(hand: str = "allegro") -> List[str]:
    """The markdown table of what each shipped checkpoint of ``hand`` cost: frames simulated for its
    training and wall-clock, as its sidecar records them, beside the issue's budget per expert.
    No simulation: read from the shipped files."""
    import json
    from unicross.rl.policy_io import read_torch_file
    lines = ["## Training budget of the shipped checkpoints", "",
             f"Frames simulated for each checkpoint's own training and its wall-clock, from its sidecar "
             f"(`unicross/checkpoints/{hand}/<name>.json`). The issue's budget for an expert: up to "
             f"{PAPER_FRAMES_PER_EXPERT:.1e} frames on a GPU (HORA-style PPO; the paper states none).", "",
             "| checkpoint | how it was trained | frames | wall-clock | hardware | frames / budget |",
             "|---|---|---|---|---|---|"]
    for name, spec in shipped(hand).items():
        path = CHECKPOINTS / hand / f"{name}.pt"
        side_path = path.with_suffix(".json")
        side = json.loads(side_path.read_text()) if side_path.exists() else {}
        ck = read_torch_file(str(path), "checkpoint")
        frames = side.get("frames", ck.get("frames"))
        wall = side.get("train_wall_s")
        note = side.get("train_wall_note")
        wall_cell = f"{wall / 60:.0f} min" if wall else "not logged" + (f" (sidecar: {note.split(',')[0]})" if note else "")
        hw = side.get("hardware") or {}
        hw_cell = f"{hw['cpus']} CPU cores" if hw.get("cpus") else "--"
        share = "--" if name == "student" or not frames else f"{frames / PAPER_FRAMES_PER_EXPERT:.1e}"
        lines.append(f"| {spec} | {how_trained(ck)} | {f'{frames:,}' if frames else 'not logged'} | "
                     f"{wall_cell} | {hw_cell} | {share} |")
    return lines + [""]


def paper_values(setting: str, hand: str = "allegro") -> Dict[str, tuple]:
    """The paper's values of ``setting`` for ``hand``, per skill: Allegro's tables, or for another hand
    its row of the hands table on test objects (the experts' and the student's tables); {} where the
    paper gives nothing for that hand."""
    if hand == "allegro":
        return PAPER[setting]
    return PAPER_HANDS.get(hand, {}) if setting in ("Experts", "Ours") else {}


def _paper(setting: str, skill: str, hand: str = "allegro") -> str:
    v = paper_values(setting, hand).get(skill)
    return "--" if v is None else " / ".join([f"{v[0]:.1f}"] + [f"{x:g}" for x in v[1:]])


def _cell(s: dict, skill: str) -> str:
    out = f"{s['sr']:.1f} [{s['ci95'][0]:.1f}-{s['ci95'][1]:.1f}] (n={s['n']})"
    if skill == "relocate":
        out += f", PE {s['pe_cm']:.2f} cm, AE {s['ae_rad']:.4f} rad"
    elif skill == "rotate":
        out += f", Rot. {s['rot_rad']:.2f} rad"
    elif skill == "translate":
        out += f", Trans. {s['trans_cm']:.1f} cm"
    return out


class PaperReport:
    """Runs the evaluations of the report (``limit`` objects per group x ``trials`` per object and
    axis, raised per cell to reach ``min_trials`` trials; ``workers`` processes) and assembles the
    markdown."""

    def __init__(self, hand: str = "allegro", limit: Optional[int] = 10, trials: int = 3, workers: int = 1,
                 seed: int = 0, min_trials: int = 100, sim: Optional[dict] = None, log: Callable[[str], None] = print):
        self.hand, self.limit, self.trials, self.workers, self.seed, self.log = hand, limit, trials, workers, seed, log
        self.sim = sim  # physics other than configs/task.yaml's for every cell (None: each policy's own)
        self.min_trials = min_trials
        self.ckpts = shipped(hand)
        from unicross.gaits import shipped_gaits
        self.gaits = shipped_gaits(hand)
        self.summaries: Dict[tuple, dict] = {}  # (mode, spec, objects, disturb) -> the cell's summary
        self.chain_summaries: Dict[str, dict] = {}  # name -> its long horizon's summary and in-hand phase by mode
        self.student_modes = list(F.MODES)
        if "student" in self.ckpts:  # a student distilled from some experts only is evaluated on those
            import torch
            ck = torch.load(CHECKPOINTS / hand / "student.pt", map_location="cpu", weights_only=False)
            self.student_modes = list(ck.get("distilled_modes") or F.MODES)

    def trials_per_object(self, n_objects: int) -> int:
        """Trials per object of a cell over ``n_objects`` objects: ``trials``, or more where that
        gives fewer than ``min_trials`` trials (the issue's n >= 100 per mode; the object set and
        its order stay those of ``limit``)."""
        return max(self.trials, math.ceil(self.min_trials / max(n_objects, 1)))

    def evaluate(self, mode: str, spec: str, objects: str, disturb: bool = False) -> str:
        """One cell: ``spec`` on the protocol of ``mode`` (its axis only) over ``objects``."""
        sk = skill_of_mode(mode)
        axis = mode_axis(mode)
        t0 = time.time()
        try:
            objs, _ = E.protocol_objects(sk.name, get_object_set(objects, limit=self.limit), self.hand)
            trials = E.run_protocol_workers(sk.name, spec, objs, hand=self.hand, workers=self.workers, seed=self.seed,
                                            trials_per_object=self.trials_per_object(len(objs)),
                                            disturb=disturb, axes=[axis] if axis else None, progress=False,
                                            sim=self.sim)
        except ValueError as e:  # e.g. no grasp states for these objects
            return f"not run: {e}"
        self.log(f"  {spec} {mode} on {objects}{' --disturb' if disturb else ''}: {time.time() - t0:.0f} s")
        summary = self.summaries[(mode, spec, objects, disturb)] = E.summarize(sk.name, trials)
        return _cell(summary, sk.name)

    def _table(self, title: str, rows: List[tuple], paper_setting: str, note: str = "") -> List[str]:
        lines = [f"## {title}", ""] + ([note, ""] if note else [])
        lines += ["| mode | policy | result [95% CI] (n) | paper (SR / metric) |", "|---|---|---|---|"]
        for mode, spec, cell in rows:
            lines.append(f"| {mode} | {spec} | {cell} | {_paper(paper_setting, skill_of_mode(mode).name, self.hand)} |")
        return lines + [""]

    def _per_mode(self, objects: str, disturb: bool, who: str) -> List[tuple]:
        rows = []
        for mode in F.MODES:
            spec = self.ckpts.get("student" if who == "student" else mode)
            if spec is None:
                gait = " (a scripted gait: see below)" if who == "expert" and mode in self.gaits else ""
                rows.append((mode, f"{who} not shipped{gait}", "--"))
            elif who == "student" and mode not in self.student_modes:
                why = "" if mode in self.ckpts else ": no expert"
                rows.append((mode, f"{spec} (not distilled for this mode{why})", "--"))
            else:
                rows.append((mode, policy_label(spec), self.evaluate(mode, spec, objects, disturb)))
        return rows

    def markdown(self, command: str) -> str:
        lines = ["# Results (regenerated from the shipped checkpoints)", "",
                 f"Command: `{command}`", "",
                 f"Hand {self.hand}; first {self.limit or 'all'} objects per (category, shape) group x "
                 f"{self.trials} trials per object and axis, more where a cell would have fewer than "
                 f"{self.min_trials} trials (each cell's n is beside it); seed {self.seed}; the paper's protocols "
                 f"(`configs/eval.yaml`). Paper values: the full test set x 25 trials"
                 + ("." if self.hand == "allegro" else
                    f"; for {self.hand} its row of the paper's hands table (one unified policy, test objects) "
                    "beside the experts and the student, and -- elsewhere (the paper's other settings are "
                    "Allegro's).")]
        if self.sim:
            lines[-1] += (" Physics: configs/task.yaml's sim section with " +
                          ", ".join(f"{k}={v}" for k, v in self.sim.items()) + " in every cell.")
        lines += ["", machine_line(), ""]
        self.log("experts on test objects ...")
        lines += self._table("Experts, held-out test objects", self._per_mode("test", False, "expert"), "Experts")
        lines += self._experts_pooled("test", False, "Experts")
        self.log("student on test objects ...")
        lines += self._table("Student, held-out test objects", self._per_mode("test", False, "student"), "Ours")
        lines += self._student_pooled("test", False, "Ours")
        self.log("unseen objects ...")
        lines += self._robustness_table("Unseen objects (spheres, hexagonal and octagonal prisms)", "unseen", False,
                                        "Uns.", "In-hand protocols start from the grasp-state dataset, so they run "
                                        "on the unseen objects that have a grasp.")
        self.log("disturbances ...")
        lines += self._robustness_table("Disturbances (`--disturb`)", "test", True, "Dis.")
        if self.gaits:
            self.log("scripted gaits ...")
            lines += self._gait_tables()
        self.log("physical references ...")
        lines += self._reference_tables()
        self.log("baselines ...")
        base = [("relocate", "scripted-relocate", self.evaluate("relocate", "scripted-relocate", "test")),
                ("relocate", "zero", self.evaluate("relocate", "zero", "test")),
                ("relocate", "zero (`--disturb`)", self.evaluate("relocate", "zero", "test", disturb=True))]
        base += [(mode, "zero", self.evaluate(mode, "zero", "test")) for mode in F.MODES if mode_axis(mode)]
        lines += self._table("Baselines: the naive relocation and the zero action", base, "Gen. (Base.)",
                             "Paper column: its retrained per-skill baselines (Gen.), not these. The zero action "
                             "on each rotate and translate axis is the bar its expert has to clear.")
        lines += training_budget(self.hand)
        lines += ["## Long horizon", ""]
        if "student" not in self.ckpts:
            lines += ["Not run: needs the student (`unicross/checkpoints/<hand>/student.pt`), which is not "
                      "shipped. Paper: " + "; ".join(f"{k} {v[-1]:g}% overall" for k, v in PAPER["long"].items()), ""]
        else:
            lines += self._long_horizon()
        return "\n".join(lines)

    def _robustness_table(self, title: str, objects: str, disturb: bool, setting: str, note: str = "") -> List[str]:
        """The paper's generalisation and robustness cells (``objects``, ``disturb``): the experts, then
        the student (the paper's own rows here are its student's), each with its rotate pool."""
        rows = self._per_mode(objects, disturb, "expert") + self._per_mode(objects, disturb, "student")
        lines = self._table(title, rows, setting, " ".join(
            ["The experts, then the student (the paper column is the paper's student)."] + ([note] if note else [])))
        return lines + self._experts_pooled(objects, disturb, setting) + self._student_pooled(objects, disturb, setting)

    def _experts_pooled(self, objects: str, disturb: bool, setting: str) -> List[str]:
        """The shipped experts' rotate cells on ``objects`` pooled (:meth:`_rotate_pooled`)."""
        return self._rotate_pooled([(m, spec, objects, disturb) for m, spec in self.ckpts.items() if m != "student"],
                                   "an expert", setting)

    def _student_pooled(self, objects: str, disturb: bool, setting: str) -> List[str]:
        """The student's rotate cells on ``objects`` pooled; nothing when no student is shipped."""
        if "student" not in self.ckpts:
            return []
        return self._rotate_pooled([(m, self.ckpts["student"], objects, disturb) for m in self.student_modes],
                                   "a distilled student", setting)

    def _gait_tables(self) -> List[str]:
        """The shipped scripted gaits (:mod:`unicross.gaits`) on test and unseen objects, and the
        success rate pooled over the rotate axes (the issue's "averaged over the six axes")."""
        lines = []
        for objects, title, setting in (("test", "held-out test objects", "Experts"),
                                        ("unseen", "unseen objects", "Uns.")):
            rows = [(mode, f"gait:{spec}", self.evaluate(mode, f"gait:{spec}", objects))
                    for mode, spec in self.gaits.items()]
            lines += self._table(
                f"Scripted finger gaits (not PPO experts), {title}", rows, setting,
                "An open-loop finger gait per mode, found by a cross-entropy search on training objects "
                "(`benchmarks/gait_search.py --hold`), run until the object has turned past the success angle "
                "(read from the task's state), then holding still: a scripted reference, not a learned policy. "
                "Rot. stays near the success angle by design (the paper's policies keep turning for 400 steps).")
            lines += self._rotate_pooled([(m, f"gait:{s}", objects, False) for m, s in self.gaits.items()],
                                         "a gait", setting)
        return lines

    def _reference_tables(self) -> List[str]:
        """The physical reference of each mode that has one (:data:`unicross.audit.PHYSICAL_REFERENCES`,
        ``--policy reference``) on test and unseen objects: the scripted bar beside its expert."""
        from unicross.audit import PHYSICAL_REFERENCES
        modes = [m for m in F.MODES if (skill_of_mode(m).name, mode_axis(m)) in PHYSICAL_REFERENCES]
        lines = []
        for objects, title, setting in (("test", "held-out test objects", "Experts"),
                                        ("unseen", "unseen objects", "Uns.")):
            rows = []
            for mode in modes:
                name, rate, joints = PHYSICAL_REFERENCES[(skill_of_mode(mode).name, mode_axis(mode))]
                what = "every finger joint" if joints is None else f"the {joints[0]} finger's {joints[1]} distal joints"
                rows.append((mode, f"reference ({name}: {what} at {rate:+g} rad per step)",
                             self.evaluate(mode, "reference", objects)))
            lines += self._table(
                f"Physical references (scripted, not policies), {title}", rows, setting,
                "A constant finger sweep that does the mode through contact alone (`--policy reference`; "
                "translate z+ opens the fingers, z- curls the index finger): the scripted bar each translate "
                "expert starts from (`model.init_reference`) and has to clear.")
        return lines

    def _rotate_pooled(self, cells: List[tuple], what: str, setting: str) -> List[str]:
        """One line: the success rate pooled over the rotate cells among ``cells`` (keys of
        :attr:`summaries`: (mode, spec, objects, disturb)) with its interval, beside the issue's
        target (>= 50% averaged over the six axes; pooled equals averaged when the axes have equal n)."""
        from unicross.metrics import wilson_interval
        rot = [self.summaries.get(c) for c in cells if skill_of_mode(c[0]).name == "rotate"]
        rot = [r for r in rot if r]
        if not rot:
            return []
        k, n = sum(r["successes"] for r in rot), sum(r["n"] for r in rot)
        lo, hi = wilson_interval(k, n)
        paper = paper_values(setting, self.hand).get("rotate")
        return [f"Rotate, pooled over the {len(rot)} axes with {what} (of 6): "
                f"{100 * k / n:.1f} [{100 * lo:.1f}-{100 * hi:.1f}] (n={n}); the issue's target for "
                f"the experts: >= 50% averaged over the six axes (paper {f'{paper[0]:.1f}' if paper else '--'}).", ""]

    def _long_horizon(self) -> List[str]:
        """The student's long horizon, then the same trials with the experts switched at each phase
        (``--policy experts:<hand>``): the teachers' side of the same cells."""
        from unicross.evaluation import make_experts_policy, resolve_policy
        missing = [m for m in F.MODES if m not in self.student_modes]
        note = ([f"The student was distilled for {', '.join(self.student_modes)} only (not for "
                 f"{', '.join(missing)}): phases of those modes are not expected to succeed.", ""] if missing else [])
        lines = note + self.chain("student", *resolve_policy(self.ckpts["student"], self.hand))
        lines += [f"The experts, each phase acted on by its mode's shipped expert (`unicross chain --policy "
                  f"experts:{self.hand}`), on the same trials: what the student's teachers do chained.", ""]
        no_expert = [m for m in F.MODES if m not in self.ckpts]
        if no_expert:
            lines += [f"Not run: no shipped expert for {', '.join(no_expert)}.", ""]
        else:
            self.log("long horizon, the experts ...")
            lines += self.chain("experts", *make_experts_policy(self.hand, self.hand, self.seed))
        return lines + ["Paper (its student): " + "; ".join(f"{k} {' / '.join(f'{x:g}' for x in v)}"
                                                            for k, v in PAPER["long"].items()), ""]

    def chain(self, name: str, policy, desc: Optional[dict] = None) -> List[str]:
        """The paper's long-horizon protocol with ``policy``: per-phase table and the in-hand phase by mode
        (the summaries kept in ``chain_summaries[name]``). It runs under the report's ``sim``, else under the
        physics the policy was made under (its description ``desc``'s ``sim``), as the report's cells."""
        from unicross.evaluation import (_own_physics, chain_last_phase_by_mode, chain_table, run_chain,
                                         summarize_chain, sr_cell)
        objs = get_object_set("test", limit=self.limit)
        # the paper's sequences split the objects: wrappable ones rotate, elongated ones translate
        per_sequence = min(sum(o.category == c for o in objs) for c in {o.category for o in objs})
        trials = run_chain(policy, objs, hand=self.hand, trials_per_object=self.trials_per_object(per_sequence),
                           seed=self.seed, progress=False, **_own_physics(dict(sim=self.sim), desc or {}))
        chains, by_mode = summarize_chain(trials), chain_last_phase_by_mode(trials)
        self.chain_summaries[name] = dict(summary=chains, in_hand_phase_by_mode=by_mode)
        by_mode_text = "; ".join(f"{m} {sr_cell(v)}" for m, v in by_mode.items())
        return [chain_table(chains), "", f"In-hand phase by mode: {by_mode_text}.", ""]


def paper_report(out: str, argv: List[str], **kwargs) -> str:
    """Write the report to ``out`` (markdown); returns its text."""
    command = "unicross " + " ".join(shlex.quote(a) for a in argv)
    text = PaperReport(**kwargs).markdown(command)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    Path(out).write_text(text + "\n")
    return text
