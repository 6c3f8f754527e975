"""The GPU branches of the reads and writes, on stand-ins for SAPIEN's GPU system (no GPU here):
``unicross.sensing.HandObjectSensor`` (the layouts it reads: body-major rows of ``cuda_rigid_body_data``,
link-major contact pairs; the scene offsets of ManiSkill's ``parallel_in_single_scene``; where the object
force is written) and the task's drive-target write. The CPU branches are checked against SAPIEN itself in
tests/test_tasks.py."""
import functools
from types import SimpleNamespace

import torch

from unicross.sensing import HandObjectSensor

N, L, DT = 3, 2, 0.01  # envs, contact links, PhysX timestep


class _GpuSystem:
    """What the sensor uses of ``sapien.physx.PhysxGpuSystem``: the body data, the pair-impulse query and
    the per-body force buffer, as tensors behind ``.torch()``."""

    def __init__(self, rows: int):
        g = torch.Generator().manual_seed(0)
        self.timestep = DT
        self.body = torch.randn(rows, 13, generator=g)
        self.force = torch.zeros(rows, 4)
        self.cuda_rigid_body_data = SimpleNamespace(torch=lambda: self.body)
        self.cuda_rigid_body_force = SimpleNamespace(torch=lambda: self.force)
        self.pairs, self.applied = None, 0

    def gpu_create_contact_pair_impulse_query(self, pairs):
        self.pairs = pairs
        impulses = torch.arange(len(pairs) * 3, dtype=torch.float32).view(len(pairs), 3)
        return SimpleNamespace(cuda_impulses=SimpleNamespace(torch=lambda: impulses), impulses=impulses)

    def gpu_query_contact_pair_impulses(self, query):
        pass

    def gpu_apply_rigid_dynamic_force(self):
        self.applied += 1


def _body(name, rows):
    """A ManiSkill struct merged over the N envs: its rows in the body data, env by env."""
    return SimpleNamespace(_body_data_index=torch.tensor(rows), _scene_idxs=torch.arange(N),
                           _bodies=[f"{name}-{e}" for e in range(N)])


def _sensor(parallel_in_single_scene: bool):
    # rows scattered over a larger buffer, as in a scene with other bodies: hand frame, 2 links, object
    rows = {"hand": [7, 1, 12], "link0": [3, 9, 0], "link1": [14, 5, 10], "obj": [2, 13, 8]}
    px = _GpuSystem(16)
    offsets = torch.tensor([[-2.0, -2.0, 0.0], [0.0, -2.0, 0.0], [2.0, -2.0, 0.0]])
    scene = SimpleNamespace(device=torch.device("cpu"), gpu_sim_enabled=True, num_envs=N, px=px,
                            parallel_in_single_scene=parallel_in_single_scene, scene_offsets=offsets)
    bodies = {k: _body(k, v) for k, v in rows.items()}
    s = HandObjectSensor(scene, bodies["hand"], [bodies["link0"], bodies["link1"]], bodies["obj"])
    return s, px, rows, offsets


def test_gpu_poses_are_env_major_and_in_each_envs_frame():
    for parallel in (False, True):
        s, px, rows, offsets = _sensor(parallel)
        pos, quat = s.poses()
        assert pos.shape == (N, 4, 3) and quat.shape == (N, 4, 4)
        for b, name in enumerate(("hand", "link0", "link1", "obj")):
            for e in range(N):
                raw = px.body[rows[name][e]]
                # parallel_in_single_scene: PhysX holds every env in one scene, shifted by its offset
                want = raw[:3] - offsets[e] if parallel else raw[:3]
                assert torch.equal(pos[e, b], want), (parallel, name, e)
                assert torch.equal(quat[e, b], raw[3:7])


def test_gpu_contact_forces_are_link_major_pairs_over_dt():
    s, px, rows, _ = _sensor(False)
    # one (link, object) pair per link and env, link-major
    assert px.pairs == [(f"link{i}-{e}", f"obj-{e}") for i in range(L) for e in range(N)]
    f = s.contact_forces()
    assert f.shape == (N, L, 3)
    imp = torch.arange(L * N * 3, dtype=torch.float32).view(L * N, 3)
    for i in range(L):
        for e in range(N):
            torch.testing.assert_close(f[e, i], imp[i * N + e] / DT)


def test_gpu_object_force_goes_to_the_objects_rows():
    s, px, rows, _ = _sensor(True)
    force = torch.tensor([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]])
    s.apply_object_force(force)
    assert px.applied == 1
    assert torch.equal(px.force[rows["obj"], :3], force)
    others = [r for r in range(16) if r not in rows["obj"]]
    assert px.force[others].abs().sum() == 0


def test_gpu_drive_targets_reach_every_env_during_a_partial_reset():
    """ManiSkill's ``set_joint_drive_targets`` keeps only the rows of the envs being reset while a reset
    runs; the task's targets are full-batch (``set_state_dict`` restores recorded states inside a partial
    reset), so the write must reach every env's row whatever the reset mask says."""
    from mani_skill.utils.structs.articulation import Articulation
    from tasks.base import UniCrossEnv
    buf = torch.zeros(N + 1, 6)  # PhysX's target buffer: articulation rows x max dof (one other articulation)
    data_index, drive_idx = torch.tensor([2, 0, 3]), torch.tensor([1, 2, 4, 5])
    applied = []
    px = SimpleNamespace(cuda_articulation_target_qpos=SimpleNamespace(torch=lambda: buf),
                         gpu_apply_articulation_target_position=lambda: applied.append(True))
    scene = SimpleNamespace(px=px, gpu_sim_enabled=True, _reset_mask=torch.tensor([False, True, False]))
    # ManiSkill's own setter on the stand-in, so that a task writing through it meets its reset mask
    robot = SimpleNamespace(scene=scene, px=px, device=torch.device("cpu"), _scene_idxs=torch.arange(N),
                            get_joint_target_indices=lambda idx: torch.meshgrid(data_index, idx, indexing="ij"))
    robot.set_joint_drive_targets = functools.partial(Articulation.set_joint_drive_targets, robot)
    task = SimpleNamespace(gpu_sim_enabled=True, agent=SimpleNamespace(robot=robot), _drive_idx=drive_idx, scene=scene)
    targets = torch.arange(N * 4, dtype=torch.float32).view(N, 4) + 1
    UniCrossEnv._apply_command(task, targets)
    assert torch.equal(buf[data_index][:, drive_idx], targets) and applied == [True]
    assert buf[1].abs().sum() == 0  # the other articulation's row is untouched
