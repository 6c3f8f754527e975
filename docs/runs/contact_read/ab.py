"""A/B of the CPU contact read (2026-12-04): the sensor's read (each point's impulse added in place to its
link's row) against the one before it (impulses and signs gathered in lists, one ``np.add.at``), in one
process, interleaved on the same held state, with bare physics of the same scene as the yardstick.

    python docs/runs/contact_read/ab.py [REPS] > docs/runs/contact_read/ab.txt

Prints, per task, that both reads give the same forces (bit for bit) and the medians of REPS repetitions
of 300 steps: steps/s and the ratio to bare physics."""
import os
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "benchmarks"))
os.environ.setdefault("UNICROSS_COMPILE", "1")
import numpy as np  # noqa: E402
import torch  # noqa: E402
from env_throughput import TASKS, _holding_env, _time_env, _time_physics, held_objects  # noqa: E402


def before(s):
    """The read before 2026-12-04 (commit 11f4a2a)."""
    obj, lookup = s._obj_body, s._link_of_body
    links, signs, impulses = [], [], []
    for c in s.scene.px.get_contacts():
        b0, b1 = c.bodies
        if b0 is obj:
            sign, link = -1.0, lookup.get(b1)
        elif b1 is obj:
            sign, link = 1.0, lookup.get(b0)
        else:
            continue
        if link is None:
            continue
        points = c.points
        impulses.extend([p.impulse for p in points])
        links.extend([link] * len(points))
        signs.extend([sign] * len(points))
    out = np.zeros((s.num_links, 3), dtype=np.float32)
    if impulses:
        np.add.at(out, links, np.asarray(impulses, dtype=np.float32) * np.asarray(signs, dtype=np.float32)[:, None])
    return torch.from_numpy(out / s.scene.px.timestep)[None]


def main():
    reps = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    gs, objs = held_objects()
    for task, kw in TASKS:
        env, u = _holding_env(task, kw, gs, objs)
        _time_env(u, 20)
        state = u.get_state_dict()
        s = u.sensor
        now = s.contact_forces
        old = (lambda: before(s))
        same = torch.equal(now(), old())
        rates = {"before": [], "now": []}
        phys = []
        for _ in range(reps):
            for name, fn in (("before", old), ("now", now)):
                s.contact_forces = fn
                u.set_state_dict(state)
                r, commands, joints, _ = _time_env(u, 300)
                rates[name].append(r)
                u.set_state_dict(state)
                phys.append(_time_physics(u, commands, joints))
        b = statistics.median(phys)
        row = {k: statistics.median(v) for k, v in rates.items()}
        print(f"{task:24s} same forces {same}  before {row['before']:6.1f}/s ({row['before'] / b:.3f})  "
              f"now {row['now']:6.1f}/s ({row['now'] / b:.3f})  physics {b:6.1f}/s  "
              f"now faster in {sum(n > o for n, o in zip(rates['now'], rates['before']))} of {reps}", flush=True)
        env.close()


if __name__ == "__main__":
    main()
