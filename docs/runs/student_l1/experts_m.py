"""rule.txt screen M1: the new rotate z- and y+ experts (shipped at 723f266) over evaluation seeds 0-3, the report's
rotate cell (rotate_seeds.py's protocol). y+: seeds 0-3 measured here; z-: seed 0 measured here, seeds 1-3 copied
from docs/runs/rotate_zm_it12/rotate_seeds_zm.json (the same checkpoint, code and protocol, 63rd session).

    python docs/runs/student_l1/experts_m.py OUT.json

OUT.json as rotate_seeds_experts.json (policy, seeds, cells: mode -> seed -> cell, successes, n); judge_i.py M reads
its two modes in place of rotate_seeds_experts.json's.
"""
import json
import os
import sys

from rotate_seeds import seed_cells  # this folder (the script's own directory is on sys.path)

HERE = os.path.dirname(os.path.abspath(__file__))
ZM = os.path.join(HERE, "..", "rotate_zm_it12", "rotate_seeds_zm.json")

if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__.split("\n\n")[1])
    cells = seed_cells("experts", ["rotate_y+"], [0, 1, 2, 3])
    cells.update(seed_cells("experts", ["rotate_z-"], [0]))
    zm = json.load(open(ZM))["cells"]["rotate_z-"]
    cells["rotate_z-"].update({int(s): c for s, c in zm.items()})
    json.dump(dict(policy="experts", seeds=[0, 1, 2, 3], cells=cells, copied={"rotate_z-": [1, 2, 3], "from": ZM}),
              open(sys.argv[1], "w"), indent=1, default=float)
