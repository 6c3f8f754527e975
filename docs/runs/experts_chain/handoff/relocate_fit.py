"""How closely does the student's relocation action follow the relocate expert's, on the chain's relocate states
and on the relocate protocol's? (diagnosis, 2026-11-27)

The relocate expert acts; at every relocate step the student's action on the same observation is computed too, and
the mean squared difference of the two (normalised actions, wrist dims and finger dims apart) is averaged over the
steps. Two sets of states, both on the first LIMIT elongated test objects per group x 3 trials, seed 0:
  * `chain`: the chain grasp -> relocate -> translate z- with the shipped experts (`unicross chain` trial seeds), its
    relocate phase (started from the grasp phase's end);
  * `dataset`: the relocate task (`UniCross-Relocate-v1`, the same seeds, as many steps as the chain's relocate phase)
    started from the grasp-state dataset, the starts the student was distilled on.

    python docs/runs/experts_chain/handoff/relocate_fit.py 20 > docs/runs/experts_chain/handoff/relocate_fit.txt
    python docs/runs/experts_chain/handoff/relocate_fit.py 20 runs/student_x/checkpoint.pt   # another student
"""
import sys

import gymnasium as gym

import unicross  # noqa: F401
from unicross import formulation as F
from unicross.evaluation import resolve_policy, trial_seed
from unicross.objects import get_object_set
from unicross.tasks.chain import PHASE_STEPS

if __name__ == "__main__":
    limit = int(sys.argv[1])
    experts, _ = resolve_policy("experts:allegro", "allegro")
    student, _ = resolve_policy(sys.argv[2] if len(sys.argv) > 2 else "allegro/student", "allegro")
    relocate = F.MODES.index("relocate")
    for where in ("chain", "dataset"):
        err_w, err_f, steps = 0.0, 0.0, 0
        for oi, obj in enumerate(get_object_set("test-elongated", limit=limit)):
            for k in range(3):
                if where == "chain":
                    env = gym.make("UniCross-Chain-v1", obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none",
                                   hand="allegro", objects=[obj], randomize=False, sequence="grasp,relocate,translate:z-")
                else:
                    env = gym.make("UniCross-Relocate-v1", obs_mode="state_dict", sim_backend="physx_cpu",
                                   render_backend="none", hand="allegro", objects=[obj], randomize=False)
                u = env.unwrapped
                obs, _ = u.reset(seed=trial_seed(0, oi, k))
                horizon = u.phase_ends[1] if where == "chain" else PHASE_STEPS["relocate"]
                for t in range(horizon):
                    a = experts(obs, u)
                    if int(u.mode[0]) == relocate:
                        d = (student(obs, u) - a) ** 2
                        err_w += float(d[0, :6].mean())
                        err_f += float(d[0, 6:].mean())
                        steps += 1
                    obs, _, term, _, _ = u.step(a)
                    if bool(term.all()):
                        break
                env.close()
        print(f"{where}: {steps} relocate steps; student - expert action, mean squared: wrist {err_w / steps:.2e}, "
              f"fingers {err_f / steps:.2e}")
