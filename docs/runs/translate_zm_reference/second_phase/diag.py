"""Per-step translation of a translate z- finger sequence on training objects (README section 1, diag.txt).

    python diag.py LIMIT TRIALS OUT.json [SPEC_FILE]

Runs the protocol (first LIMIT training objects per group x TRIALS, seed 0) and prints per episode: S success, D drop,
- neither; the final translation (cm); the translation accumulated along z- every 5 control steps (cm).
"""
import json
import sys

import numpy as np
import torch

import unicross  # noqa
from unicross import evaluation as E
from unicross.objects import get_object_set
from unicross.sequences import make_sequence_policy
torch.set_num_threads(1)
spec = open(sys.argv[4] if len(sys.argv) > 4 else 'docs/runs/translate_zm_reference/it12_search/chosen.txt').read().strip()
base = make_sequence_policy(spec)
log = []
cur = [None]
def pol(obs, u):
    t = int(u.elapsed_steps[0])
    if t == 0:
        cur[0] = {'names': list(u.hand_spec.finger_joints)}; log.append(cur[0])
    cur[0].setdefault('trans', []).append(float(u.trans_acc[0]))
    cur[0].setdefault('cmd', []).append(u.command[0, 6:].tolist())
    return base(obs, u)
objs = get_object_set('train', limit=int(sys.argv[1]))
trials = E.run_protocol('translate', pol, objs, trials_per_object=int(sys.argv[2]), seed=0, axes=['z-'], progress=False)
out = []
for tr, lg in zip(trials, log):
    out.append(dict(success=tr['success'], dropped=tr['dropped'], tcm=tr['translation_cm'], obj=tr['object'], trans=lg['trans'], cmd=lg['cmd'], names=lg['names']))
json.dump(out, open(sys.argv[3], 'w'))
for o in out:
    tr = np.array(o['trans']) * 100
    print(o['obj'][:28], 'S' if o['success'] else ('D' if o['dropped'] else '-'), f"{o['tcm']:.1f}", ' '.join(f"{tr[i]:.1f}" for i in range(0, len(tr), 5)))
