"""Reward audit of translate z- finger sequences (docs/runs/translate_zm_reference/README.md): the discounted,
scaled return PPO sees for the zero action, the index pull and the pull with the state-triggered ring, in the
training env (its randomisation), 4 training objects per group x 3 seeds. Output: audit_sequences.txt.

    python docs/runs/translate_zm_reference/audit_sequences.py
"""
import torch

from unicross.audit import audit
from unicross.sequences import make_sequence_policy

torch.set_num_threads(1)
SEQUENCES = {"zero": "index:2:0.0:0:1", "pull": "index:2:0.05:0:1000",
             "pull+ring@0.9": "index:2:0.05:0:1000+ring:2:0.05:@index:0.9"}


def factory(spec):
    """audit's behaviour factory: u -> act()."""
    def make(u):
        policy = make_sequence_policy(spec)
        return lambda: policy(None, u)
    return make


if __name__ == "__main__":
    rows = audit("translate", "z-", limit=4, seeds=3, progress=False,
                 behaviour_set={k: factory(v) for k, v in SEQUENCES.items()})
    for r in rows:
        print(f"{r.behaviour:16s} total {r.total:8.3f}  success {r.success:.3f}  episodes {r.episodes}  terms "
              + " ".join(f"{k}={v:.2f}" for k, v in r.terms.items()))
