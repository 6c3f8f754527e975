"""Amendment (c) of rule.txt: the candidate against the replaced z+ expert on the unseen and --disturb z+ cells over
evaluation seeds 0-3, paired by trial (`../translate_zm_chain/judge.py --guard` now applies the same bar). Reverts the ship if
either is more than 5 points under with the paired 95%
interval below 0.

    python docs/runs/rotate_zp_chain/guard.py > docs/runs/rotate_zp_chain/guard.txt
"""
import gzip
import json
import math

D = "docs/runs/rotate_zp_chain/data"
revert = False
for setting, name in (("unseen", "unseen objects"), ("dist", "test objects, --disturb")):
    side = {}
    for who in ("shipped", "cand"):
        side[who] = {}
        for s in range(4):
            d = json.loads(gzip.decompress(open(f"{D}/{setting}_{who}_s{s}.json.gz", "rb").read()))
            side[who].update({(s, t["object"], t["trial"]): bool(t["success"]) for t in d["trials"]["rotate"]})
    keys = sorted(side["shipped"])
    assert keys == sorted(side["cand"]), "not the same trials"
    a = [side["shipped"][k] for k in keys]
    b = [side["cand"][k] for k in keys]
    n = len(keys)
    d = [int(y) - int(x) for x, y in zip(a, b)]
    m = sum(d) / n
    h = 1.96 * math.sqrt(sum((x - m) ** 2 for x in d) / (n - 1) / n)
    pa, pb = 100 * sum(a) / n, 100 * sum(b) / n
    bad = pb < pa - 5 and m + h < 0
    revert |= bad
    print(f"rotate z+, {name}, evaluation seeds 0-3 (n = {n}): replaced {pa:.1f}%, candidate {pb:.1f}%, paired "
          f"{100 * m:+.1f} [{100 * (m - h):+.1f}, {100 * (m + h):+.1f}]: {'REVERT' if bad else 'within the guard'}")
print("REVERT" if revert else "STAYS SHIPPED")
