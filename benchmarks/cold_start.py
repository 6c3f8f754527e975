"""Time until N env workers are ready with an empty Inductor cache (every worker compiles the
step math, or loads what another one wrote): the start-up cost of a run on a fresh machine.

    python benchmarks/cold_start.py 2          # N = 2 workers; prints the seconds

Each worker prints its own compile time on stderr ("step math compiled in X s"). UNICROSS_COMPILE=0
makes this the eager start-up time.
"""
import os
import sys
import tempfile
import time


def main() -> None:
    os.environ["TORCHINDUCTOR_CACHE_DIR"] = tempfile.mkdtemp(prefix="inductor_cold_")  # before torch
    from unicross.rl.collector import LeanCollector
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 2
    t0 = time.perf_counter()
    c = LeanCollector("UniCross-Grasp-v1", dict(object_limit=1), num_envs=n, horizon=4, seed=0)
    print(f"{n} workers ready (empty Inductor cache) in {time.perf_counter() - t0:.1f} s", flush=True)
    c.close()


if __name__ == "__main__":  # workers are spawned: they import this file again
    main()
