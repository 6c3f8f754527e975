"""Which envs a DAgger env worker steps with ``env.chain_share`` (the stage's settings), in one process: episodes and
steps in the multi-skill env and in each chain (the alternates), with the stage's student acting (its mean action,
as DAgger's workers do).

    python docs/runs/student_chain_starts/check_mix.py CHECKPOINT [SHARE=0.3] [STEPS=20000]
"""
import collections
import sys

from unicross.rl.collector import Rollout, make_buffer
from unicross.rl.dagger import chain_envs
from unicross.rl.policy_io import load_policy

if __name__ == "__main__":
    ckpt, share = sys.argv[1], float(sys.argv[2]) if len(sys.argv) > 2 else 0.3
    steps = int(sys.argv[3]) if len(sys.argv) > 3 else 20000
    pol, ck = load_policy(ckpt, "cpu")
    kw = dict(ck["env_kwargs"], sim_backend="physx_cpu", num_envs=1)
    alt = [(i, dict(k, sim_backend="physx_cpu", num_envs=1)) for i, k in chain_envs(ck["env_kwargs"], share)]
    ro = Rollout("UniCross-MultiSkill-v1", kw, seed=0, deterministic=True, alternates=alt, alternate_share=share)
    ro.set_actor(pol.module[0].module)
    episodes, frames = collections.Counter(), collections.Counter()
    names = ["multi-skill"] + ["chain " + k["sequence"][-1] for _, k in alt]
    reset_done = ro._reset_done

    def counted(done):
        slot = next(k for k, v in ro._slots.items() if v[1] is ro.task)
        episodes[names[slot]] += 1
        frames[names[slot]] += int(ro.task.elapsed_steps[0])
        return reset_done(done)

    ro._reset_done = counted
    for _ in range(steps // 500):
        ro.collect(make_buffer(1, 500, ro.dims, ro.n_act))
    total = sum(frames.values())
    print(f"{sum(episodes.values())} episodes ended, {total} of their steps; in chains: "
          f"{sum(v for k, v in episodes.items() if k != 'multi-skill') / max(1, sum(episodes.values())):.2f} of episodes, "
          f"{sum(v for k, v in frames.items() if k != 'multi-skill') / max(1, total):.2f} of steps")
    for k in names:
        print(f"  {k}: {episodes[k]} episodes, {frames[k]} steps")
    ro.close()
