"""Why does a second process miss Inductor's on-disk cache for a GraphMethod graph on the lent machine?
Runs docs/runs/device16/cache_probe.py's toy with the cache keys recorded: every (key, hash details)
that AOTAutograd's cache (``autograd_cache_key``, looked up first) and Inductor's FX graph cache
(``compiled_fx_graph_hash``, on a miss of the former) compute is written to ``$OUT/hash_<tag>.txt``;
run it twice (tags a and b) and diff the files: a line that differs names what changes the key.
    python docs/runs/device16_overlap/hash_probe.py a; python docs/runs/device16_overlap/hash_probe.py b"""
import os
import runpy
import sys

from torch._functorch._aot_autograd import autograd_cache
from torch._inductor import codecache

tag = sys.argv[1] if len(sys.argv) > 1 else "a"
out = os.environ.get("OUT", "/tmp")
records = []


def recording(module, name):
    orig = getattr(module, name)

    def fn(*args, **kwargs):
        key, lines = orig(*args, **kwargs)
        records.append((name, key, lines))
        with open(os.path.join(out, f"hash_{tag}.txt"), "w") as f:
            for n, k, ls in records:
                f.write(f"{n} KEY {k}\n" + "\n".join(ls) + "\n")
        return key, lines

    setattr(module, name, fn)


recording(autograd_cache, "autograd_cache_key")
recording(codecache, "compiled_fx_graph_hash")
runpy.run_path(os.path.join(os.getcwd(), "docs", "runs", "device16", "cache_probe.py"), run_name="__main__")
print(f"[{tag}] keys: {[(n, k) for n, k, _ in records]}")
