"""rule.txt step 3: a sequence spec against another on every training stick x 2 starts (seed 500), thin sticks and
all, as ../whole_set/search3.py's selection runs them (its search2's selection measured the shipped sequence at 321/400).

    python docs/runs/translate_zm_reference/thickness/teacher_train.py "$(cat teacher.txt)" "$(cat ../second_phase/chosen.txt)"
"""
import multiprocessing as mp
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "whole_set"))
import search3  # noqa: E402

if __name__ == "__main__":
    pool = mp.get_context("spawn").Pool(2)
    for name, spec in (("switched teacher", sys.argv[1]), ("shipped sequence", sys.argv[2])):
        for label, names in (("thin", search3.sticks(0.049)), ("all", search3.sticks())):
            score, ok, drops, n = search3.run(pool, spec, 500, names, 2, 2)
            print(f"{name}: {label} training sticks {ok}/{n} drops {drops}", flush=True)
