"""Renders each trajectory given with SAPIEN (``unicross.render.render_frames(..., renderer="sapien")``)
in one process: a 640x480 still of the last frame (PNG), an animation of every 3rd step at 320x240
(GIF), and the seconds each took; one JSON line per trajectory on stdout.

    python render_all.py OUT_DIR TRAJ.npz ...   (the device run: docs/runs/device16_render/run.sh)
"""
import json
import sys
import time
from pathlib import Path

import imageio.v2 as imageio
from PIL import Image

from unicross.render import render_frames
from unicross.trajectory import Trajectory

out = Path(sys.argv[1])
for path in sys.argv[2:]:
    name = Path(path).stem
    traj = Trajectory.load(path)
    camera = "follow" if name.startswith("grasp") else "front"
    row = dict(trajectory=name, steps=len(traj), camera=camera)
    t = time.perf_counter()
    still = render_frames(traj, camera, 640, 480, [len(traj) - 1], renderer="sapien")[0]
    row["still_s"] = round(time.perf_counter() - t, 2)
    imageio.imwrite(out / f"{name}.png", still)
    idx = list(range(0, len(traj), 3))
    t = time.perf_counter()
    frames = render_frames(traj, camera, 640, 480, idx, renderer="sapien")
    row.update(frames=len(frames), frames_s=round(time.perf_counter() - t, 2))
    small = [Image.fromarray(f).resize((320, 240), Image.LANCZOS) for f in frames]
    fps = traj.meta.get("control_freq", 20)
    small[0].save(out / f"{name}.gif", save_all=True, append_images=small[1:], duration=int(1000 * 3 / fps), loop=0)
    print(json.dumps(row), flush=True)
