"""The three --progress clones of the stopping y- gait on the 120 held-out trials, against the clone of the same gait
without the input and against the three no-stop clones, paired by trial (run from the repository root):

    python docs/runs/nostop/progress_input/summary.py
"""
import json, sys
sys.path.insert(0, 'docs/runs/paper_protocol')
from paired import newcombe_paired, mcnemar_exact
from unicross.metrics import wilson_interval as wilson
def key(t): return (t['object'], t.get('axis'), t['trial'], t.get('seed'))
def load(p): return {key(t): t for t in json.load(open(p))['trials']}
ctrl = load('docs/runs/gait_clone/phase_rounds8/r8_ym_phase_searched/heldout.json')
ship = load('docs/runs/nostop/clone_y-_shipped/heldout.json')
runs = [load(f'docs/runs/nostop/progress_input/clone_s{s}/heldout.json') for s in range(3) if __import__('os').path.exists(f'docs/runs/nostop/progress_input/clone_s{s}/heldout.json')]
for i, r in enumerate(runs):
    k = sum(bool(t['success']) for t in r.values()); d = sum(bool(t.get('dropped')) for t in r.values())
    short = sum(1 for t in r.values() if not t['success'] and not t.get('dropped'))
    print(f"seed {i}: {k} of {len(r)} ({100*k/len(r):.1f}%), dropped {d}, held short {short}")
def pooled_vs(other, name):
    a = b = c = d = 0
    for r in runs:
        for kk, t in r.items():
            x, y = bool(t['success']), bool(other[kk]['success'])
            a += x and y; b += x and not y; c += y and not x; d += (not x) and (not y)
    n = a + b + c + d
    lo, hi = newcombe_paired(a, b, c, d)
    print(f"pooled {a+b} of {n} ({100*(a+b)/n:.1f}% [{100*wilson(a+b,n)[0]:.1f}-{100*wilson(a+b,n)[1]:.1f}]) vs {name} x{len(runs)} {a+c}: {100*(b-c)/n:+.1f} [{100*lo:+.1f}, {100*hi:+.1f}] won {b} lost {c} p={mcnemar_exact(b,c):.3g}")
pooled_vs(ctrl, "the stop clone without the input (one seed, repeated: descriptive only)")
nostop = [ship, load('docs/runs/nostop/clone_y-_s1/heldout.json'), load('docs/runs/nostop/clone_y-_s2/heldout.json')]
a = b = c = d = 0
for r, o in zip(runs, nostop):
    for kk, t in r.items():
        x, y = bool(t['success']), bool(o[kk]['success'])
        a += x and y; b += x and not y; c += y and not x; d += (not x) and (not y)
n = a + b + c + d
lo, hi = newcombe_paired(a, b, c, d)
print(f"seed by seed vs the no-stop clones' seeds 0..{len(runs)-1}: {a+b} vs {a+c} of {n}: {100*(b-c)/n:+.1f} [{100*lo:+.1f}, {100*hi:+.1f}] won {b} lost {c} p={mcnemar_exact(b,c):.3g}")
