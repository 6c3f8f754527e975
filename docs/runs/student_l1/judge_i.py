"""rule.txt screens I (step I3), J (J3), K (K3) and L (L3): the three seeds' students against their experts, rotate
cells (and for K and L the long-horizon cells) over four evaluation seeds.

    python docs/runs/student_l1/judge_i.py [SCREEN] > docs/runs/student_l1/judge_<screen>.txt

SCREEN (default I) names the students: I, x+ weight 10 on training seeds 4, 5, 6 (tag _w10ship); J, x+ weight 5 on
seeds 7, 8, 9 (tag _w5ship); K, J's recipe on seeds 10, 11, 12; L, K's with env.chain_repeats={rotate_x+: 1,
translate_z-: 3} on seeds 13, 14, 15 (tag _chz); M, K's stage from K's initial student with the new z- and y+
experts on seeds 16, 17, 18 (tag _m). Rotate cells: the student's successes pooled over its three training seeds and evaluation
seeds 0-3 (n = 1200; seed 0 from student_cells_rep3TAG_sS.json, 1-3 from rotate_seeds_rep3TAG_sS.json) against the mode's shipped
expert over evaluation seeds 0-3 (rotate_seeds_experts.json, n = 400) minus 5 points. Every other cell as judge3.py:
the evaluation-seed-0 cells pooled over the three students against docs/results.md's expert cell - 5 (grasp,
relocate, translate) and the shipped student's long horizon - 5; for K each long-horizon cell is pooled as the rotate
cells (seeds 1-3 from chain_seeds_rep3TAG_sS.json) against the shipped student over evaluation seeds 0-3
(chain_seeds_shipped.json, n = 400) minus 5 points; for L against K's seed 10, shipped since (its seed-0 cells and
chain_seeds_rep3_w5ship_s10.json, n = 400) minus 5 points, and L passes only when its pooled Gr. + Re. + Trans. also
has its 95% lower bound above that student's rate (L3: a gain). M as L, with the z- and y+ experts' cells from
rotate_seeds_experts_m.json; a missed z- or y+ bar is excused (M3b) when every other bar is met and that cell's pooled
95% lower bound is above K's seed 10 over evaluation seeds 0-3 (a gain over the shipped student). N as M: M's three
runs resumed to epoch 2000 at lr 3e-5 (tag _n); O as M: M's three runs resumed to epoch 2000 with the grasp rows
weighted 3 (tag _o); P as O: O's three runs resumed to epoch 2500 with the z+ expert shipped at 564f969 (tag _p), its
z+ bar from that expert (rotate_seeds_experts_p.json), the long horizon and the excusable z+ cell (P3) against O's
seed 16 (shipped by O); Q as P on new DAgger seeds (tag _q), its translate cells pooled over evaluation seeds 0-3
against the experts' (translate_seeds_experts.json) as the rotate cells. The last line is PASSED or FAILED (ship.py reads it).
"""
import importlib.util
import json
import os
import sys

from unicross.metrics import wilson_interval

HERE = os.path.dirname(os.path.abspath(__file__))
# the export's tag, the training seeds, whether the long horizon pools evaluation seeds 0-3
SCREENS = {"I": ("_w10ship", (4, 5, 6), False), "J": ("_w5ship", (7, 8, 9), False), "K": ("_w5ship", (10, 11, 12), True),
           "L": ("_chz", (13, 14, 15), True), "M": ("_m", (16, 17, 18), True), "N": ("_n", (16, 17, 18), True),
           "O": ("_o", (16, 17, 18), True), "P": ("_p", (16, 17, 18), True),
           "Q": ("_q", (16, 17, 18), True)}
M_LIKE = ("M", "N", "O", "P", "Q")  # the screens judged with M's references (M1, M3b); P and Q with their own beside them
NEW_EXPERTS = "rotate_seeds_experts_m.json"  # M1: the z- and y+ experts shipped since K
L_REF_ROTATE = "rotate_seeds_rep3_w5ship_s10.json"  # M3b: the shipped student's rotate cells under seeds 1-3
# L's long-horizon reference: K's seed 10 (shipped by K), its evaluation-seed-0 cells and seeds 1-3
L_REF = ("student_cells_rep3_w5ship_s10.json", "chain_seeds_rep3_w5ship_s10.json")
# P1: the z+ expert shipped at 564f969 over evaluation seeds 0-3; P's long horizon and its excused z+ cell (P3)
# against O's seed 16 (shipped by O): its evaluation-seed-0 cells, the long horizon and rotate cells under seeds 1-3
P_EXPERTS = "rotate_seeds_experts_p.json"
O_REF = ("student_cells_rep3_o_s16.json", "chain_seeds_rep3_o_s16.json")
O_REF_ROTATE = "rotate_seeds_rep3_o_s16.json"
# Q1: the translate experts over evaluation seeds 0-3; Q's translate cells pool seeds 0-3 as the rotate cells
Q_TRANSLATE = "translate_seeds_experts.json"
GAIN = "Gr. + Re. + Trans."  # L3: the chain that must gain
EVAL_SEEDS = ("0", "1", "2", "3")
spec = importlib.util.spec_from_file_location("judge3", os.path.join(HERE, "..", "student_xp_drift", "judge3.py"))
judge3 = importlib.util.module_from_spec(spec)
spec.loader.exec_module(judge3)


def ci(k, n):
    lo, hi = (100 * x for x in wilson_interval(k, n))
    return f"{100 * k / n:.1f} [{lo:.1f}-{hi:.1f}] (n={n})"


def over_seeds(ref, seed0, rest):
    """A cell pooled over evaluation seeds 0-3: ``ref`` the reference's {seed: {successes, n}}; per student its
    seed-0 summary (``seed0``, the report's cell) and its {seed: {successes, n}} of seeds 1-3 (``rest``). Returns
    the students' pooled successes and n, each student's rate and the reference's (successes, n)."""
    per_k, per_n = zip(*[[s[f] + sum(r[e][f] for e in EVAL_SEEDS[1:]) for f in ("successes", "n")]
                         for s, r in zip(seed0, rest)])
    kr, nr = (sum(ref[e][f] for e in EVAL_SEEDS) for f in ("successes", "n"))
    return sum(per_k), sum(per_n), [100 * a / b for a, b in zip(per_k, per_n)], (kr, nr)


if __name__ == "__main__":
    screen = sys.argv[1] if len(sys.argv) > 1 else "I"
    if len(sys.argv) > 2 or screen not in SCREENS:
        sys.exit(f"usage: python judge_i.py [SCREEN], SCREEN one of {', '.join(SCREENS)}")
    tag, seeds, chain_seeds = SCREENS[screen]
    cells_files = [os.path.join(HERE, f"student_cells_rep3{tag}_s{s}.json") for s in seeds]
    rot_files = [os.path.join(HERE, f"rotate_seeds_rep3{tag}_s{s}.json") for s in seeds]
    chain_files = [os.path.join(HERE, f"chain_seeds_rep3{tag}_s{s}.json") for s in seeds] if chain_seeds else []
    ref_cells, ref_rotate = (O_REF, O_REF_ROTATE) if screen in ("P", "Q") else (L_REF, L_REF_ROTATE)
    refs = list(ref_cells) if screen in ("L", *M_LIKE) else ["chain_seeds_shipped.json"]
    chain_files += [os.path.join(HERE, f) for f in refs] if chain_seeds else []
    extra = [os.path.join(HERE, f) for f in (NEW_EXPERTS, ref_rotate)] if screen in M_LIKE else []
    extra += [os.path.join(HERE, P_EXPERTS)] if screen in ("P", "Q") else []
    extra += [os.path.join(HERE, Q_TRANSLATE)] if screen == "Q" else []
    missing = [f for f in cells_files + rot_files + chain_files + extra if not os.path.exists(f)]
    if missing:
        sys.exit("missing: " + ", ".join(missing))
    experts = json.load(open(os.path.join(HERE, "rotate_seeds_experts.json")))["cells"]
    new_experts = json.load(open(os.path.join(HERE, NEW_EXPERTS)))["cells"] if screen in M_LIKE else {}
    experts.update(new_experts)
    excused_modes = set(new_experts)  # M3b: the cells a miss of which may be excused by a gain
    if screen in ("P", "Q"):
        replaced = json.load(open(os.path.join(HERE, P_EXPERTS)))["cells"]
        experts.update(replaced)
        new_experts = {**new_experts, **replaced}
        excused_modes = set(replaced)
    over_four = ("rotate_",)  # the cells pooled over evaluation seeds 0-3 against the experts' four seeds
    if screen == "Q":
        translate = json.load(open(os.path.join(HERE, Q_TRANSLATE)))["cells"]
        experts.update(translate)
        new_experts = {**new_experts, **translate}
        over_four += ("translate_",)
    excusable = {}  # M3b: mode -> (pooled lower bound, the shipped student's rate over seeds 0-3)
    pool, cells = judge3.pooled(cells_files)
    rots = [json.load(open(f))["cells"] for f in rot_files]
    chains = [json.load(open(f)) for f in chain_files]
    if screen in ("L", *M_LIKE):  # the reference's seed-0 cells from its report cells, seeds 1-3 from its chain_seeds file
        seed0, rest = chains.pop(-2), chains.pop()
        chains.append({c: {"0": seed0["long_horizon"]["summary"][c]["overall"], **rest["cells"][c]}
                       for c in rest["cells"]})
    chains = [c.get("cells", c) for c in chains]
    gain = None
    shipped = json.load(open(os.path.join(HERE, "..", "translate_zm_reference", "thickness",
                                          "student_cells_seed0.json")))
    ok = True
    missed = []  # M: missed z- or y+ bars, judged by M3b below
    print("| cell | " + " | ".join(f"seed {s}" for s in seeds) + " | student pooled [95% CI] | expert [95% CI] | bar | |")
    print("|---|---|---|---|---|---|---|---|")
    for name, (k, n) in pool.items():
        if name.startswith(over_four):
            ex = experts[name]
            measured = 100 * ex["0"]["successes"] / ex["0"]["n"]
            if measured != judge3.EXPERT[name] and name not in new_experts:
                print(f"note: {name}: the expert's seed-0 cell measured {measured:g}, "
                      f"docs/results.md {judge3.EXPERT[name]:g}")
            k, n, per, (ke, ne) = over_seeds(ex, [c["test"][name]["summary"] for c in cells], [r[name] for r in rots])
            expert = ci(ke, ne)
            bar = 100 * ke / ne - 5
            if name in excused_modes:
                ref0 = json.load(open(os.path.join(HERE, ref_cells[0])))["test"][name]["summary"]
                ref = json.load(open(os.path.join(HERE, ref_rotate)))["cells"][name]
                kr, nr, _, _ = over_seeds(ex, [ref0], [ref])  # the shipped student as one student over seeds 0-3
                excusable[name] = (100 * wilson_interval(k, n)[0], 100 * kr / nr)
        elif name in judge3.EXPERT:
            per = [c["test"][name]["summary"]["sr"] for c in cells]
            expert = f"{judge3.EXPERT[name]:g} (n=100+, seed 0)"
            bar = judge3.EXPERT[name] - 5
        elif chain_seeds:
            ref = chains[-1][name]
            measured = 100 * ref["0"]["successes"] / ref["0"]["n"]
            docs = shipped["long_horizon"]["summary"][name]["overall"]["sr"]
            if screen == "K" and measured != docs:
                print(f"note: {name}: the shipped student's seed-0 cell measured {measured:g}, recorded {docs:g}")
            k, n, per, (kr, nr) = over_seeds(ref, [c["long_horizon"]["summary"][name]["overall"] for c in cells],
                                             [r[name] for r in chains[:-1]])
            expert = f"shipped student {ci(kr, nr)}"
            bar = 100 * kr / nr - 5
            if screen == "L" and name == GAIN:
                gain = (100 * wilson_interval(k, n)[0], 100 * kr / nr)
        else:
            per = [c["long_horizon"]["summary"][name]["overall"]["sr"] for c in cells]
            ref = shipped["long_horizon"]["summary"][name]["overall"]["sr"]
            expert = f"shipped student {ref:g}"
            bar = ref - 5
        good = 100 * k / n >= bar - 1e-9
        if not good and name in excusable:
            missed.append(name)
        else:
            ok &= good
        print(f"| {name} | " + " | ".join(f"{p:.1f}" for p in per) + f" | {ci(k, n)} | {expert} | >= {bar:.2f} | "
              f"{'ok' if good else 'MISSED'} |")
    if gain is not None:
        lo, rate = gain
        print(f"L3 gain: {GAIN} pooled lower bound {lo:.2f} {'>' if lo > rate else '<='} the shipped student's "
              f"{rate:.2f}: {'ok' if lo > rate else 'MISSED'}")
        ok &= lo > rate
    for name in missed:
        lo, rate = excusable[name]
        gained = lo > rate
        print(f"M3b: {name} missed its bar (the issue's target); pooled lower bound {lo:.2f} "
              f"{'>' if gained else '<='} the shipped student's {rate:.2f} over seeds 0-3: "
              f"{'a gain' if gained else 'MISSED'}")
        ok &= gained
    print(f"rule.txt {screen}3: {'PASSED' if ok else 'FAILED'}"
          + (f" (M3b: {', '.join(missed)} below the issue's target)" if ok and missed else ""))
    sys.exit(0 if ok else 1)
