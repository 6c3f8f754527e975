"""Where does a cache hit of the toy GraphMethod spend its time on the lent machine? Runs
hash_probe.py under cProfile and prints the slowest functions (cumulative) and every compiler
command run, with its duration.
    python docs/runs/device16_overlap/profile_probe.py b   (after hash_probe.py a warmed the cache)"""
import cProfile
import os
import pstats
import runpy
import subprocess
import sys
import time

_run = subprocess.Popen.__init__
commands = []


def logged(self, args, *a, **k):
    commands.append((time.perf_counter(), args if isinstance(args, str) else " ".join(map(str, args))))
    return _run(self, args, *a, **k)


subprocess.Popen.__init__ = logged
prof = cProfile.Profile()
t0 = time.perf_counter()
prof.runcall(runpy.run_path, os.path.join(os.path.dirname(__file__), "hash_probe.py"), run_name="__main__")
print(f"total {time.perf_counter() - t0:.1f} s; {len(commands)} subprocesses:")
for t, c in commands:
    print(f"  at {t - t0:6.1f} s: {c[:400]}")
st = pstats.Stats(prof, stream=sys.stdout)
st.sort_stats("cumulative").print_stats(45)
st.sort_stats("tottime").print_stats(15)
