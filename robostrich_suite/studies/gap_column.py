"""The gap measure: how tall a vertical column of level poses a routing holds through a slot.

The narrow gap of the paper's Fig. 10 asks the head to rise straight up through a shelf,
level at every sub-target.  That needs level poses with the head at one x, at several
heights, whose necks all come up through the shelf's slot (7 cm wide in the arm's plane),
and a way from each to the next that keeps the neck in the slot.  For a set of held poses
this module finds the best place for such a shelf and measures the column it allows:

* a **scene** is the task's obstacle with its slot moved along x to suit the routing: the slot's
  centre ``slot_x`` (from the arm's base joint, C18) is free, the shelf's underside ``shelf_z`` is
  the task's (:data:`SHELF_Z`: 0.50 m above the ground, 0.133 m above the standing quadruped's
  mount; the robot may stand nearer or walk under the shelf, it cannot change its height), the
  shelf ``scenes.GAP_SHELF_THICKNESS`` thick, the wall ``scenes.GAP_SLOT_X`` behind the slot above
  the shelf and the ground ``scenes.NOMINAL_MOUNT_HEIGHT`` below the base joint;
* a pose is **in the column** of a scene when it is held at rest with the head level (90 +- 5 deg),
  the head within :data:`COLUMN_TOLERANCE` of the slot's centre in x and above the shelf, and no
  point of the arm's capsules touches the scene: its neck then crosses the shelf's plane inside
  the slot and nowhere else;
* neighbouring poses of a column (sorted by height) are at most :data:`MAX_STEP` apart in
  height, and ``connected(a, b, scene)`` must hold for each pair: in simulation
  (:func:`ramp_stays_clear`) the inputs ramped from one to the other keep every capsule clear of
  the scene and end at the other pose;
* the **column height** is the head-height range of the tallest such run, over every slot position,
  or over those of a range ``slot_x`` = (min, max) (``robostrich-design --slot-x``: the slot held
  where the task puts it, :data:`TASK_NEED`'s ``slot_x_m``).

It is measured on the arm on its frame, in the base joint's frame: the standing quadruped holds
the mount still, so its poses are the frame's moved by ``quadruped_tasks.FRAME_TO_TRUNK_OFFSET``
(as the tasks' targets are), at a fraction of the simulation.  The trunk is not an obstacle here.

A level head cannot pass the slot itself (6 cm long plus its 2.6 cm thickness against 7 cm), so
the task's sub-targets above the shelf (5 and 6, 0.56 and 0.60 m, the shelf's top at 0.53 m) are the
part of Fig. 10 a column of level poses can hold: :data:`TASK_NEED` in the base joint's frame.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from robostrich_suite import physics as physics_lib
from robostrich_suite import scenes
from robostrich_suite.tasks.conventions import LEVEL_ATTITUDE_DEG, LEVEL_TOLERANCE_DEG
from robostrich_suite.studies import pose_seek, workspace

COLUMN_TOLERANCE = 0.02  # m: a column's heads lie within this of the slot's centre in x
MAX_STEP = 0.05  # m between neighbouring heads of a column: the tasks' position tolerance
SAMPLES_PER_CAPSULE = 5  # points along each capsule's axis
GRID = 0.005  # m between the slot centres tried
RAMP_TIME = 1.0  # s of a ramp between neighbouring poses' inputs
RAMP_HOLD = 1.0  # s held at the end of a ramp
ARRIVAL = 0.02  # m: a ramp ends at the other pose when its head comes this near
MAX_RAMPS = 24  # ramps simulated per measure: the cheap score of a search trial
SHELF_DEPTH_PAST_SLOT = scenes.GAP_SHELF_DEPTH - scenes.GAP_SLOT_X - scenes.GAP_SLOT_WIDTH / 2
WALL_BEHIND_SLOT = scenes.GAP_SLOT_X  # m from the slot's centre to the wall's near face

# The task's slot and sub-targets 5 and 6 in the base joint's frame (standing quadruped, stopped
# GAP_STOP_DISTANCE from the wall): what a column must hold for Fig. 10's rise above the shelf.
_MOUNT_TO_SLOT = 0.16 + scenes.GAP_SLOT_X  # quadruped_tasks.GAP_STOP_DISTANCE + the slot behind the wall
SHELF_Z = scenes.GAP_SHELF_BOTTOM - scenes.NOMINAL_MOUNT_HEIGHT  # m above the base joint: the task's shelf
TASK_NEED = {
    "slot_x_m": round(_MOUNT_TO_SLOT, 3),
    "shelf_z_m": round(SHELF_Z, 3),
    "heads_z_m": [round(z - scenes.NOMINAL_MOUNT_HEIGHT, 3) for z in (0.56, 0.60)],
    "column_height_m": 0.04,
}


@dataclasses.dataclass(frozen=True)
class Scene:
    """The narrow gap's obstacle placed at ``slot_x``, ``shelf_z`` (base joint frame, m)."""
    slot_x: float
    shelf_z: float

    def boxes(self) -> np.ndarray:
        """(4, 4) rectangles [x0, x1, z0, z1] in the arm's plane: near shelf, far shelf, wall, ground."""
        half, top = scenes.GAP_SLOT_WIDTH / 2, self.shelf_z + scenes.GAP_SHELF_THICKNESS
        wall = self.slot_x - WALL_BEHIND_SLOT
        return np.array([
            [wall - scenes.WALL_THICKNESS, self.slot_x - half, self.shelf_z, top],
            [self.slot_x + half, self.slot_x + half + SHELF_DEPTH_PAST_SLOT, self.shelf_z, top],
            [wall - scenes.WALL_THICKNESS, wall, top, 10.0],
            [-10.0, 10.0, -10.0, -scenes.NOMINAL_MOUNT_HEIGHT],
        ])

    def touches(self, points: np.ndarray, radii: np.ndarray) -> np.ndarray:
        """(...,) bool: poses whose capsule points (..., m, 2) of radii (m,) touch a box."""
        return touching(points, radii, self.boxes())


def touching(points, radii, boxes) -> np.ndarray:
    """Per pose (leading axes of ``points``, (..., m, 2)): any point within its radius of a box."""
    x, z = points[..., 0, None], points[..., 1, None]  # (..., m, 1) against (b,)
    dx = np.maximum(np.maximum(boxes[:, 0] - x, x - boxes[:, 1]), 0.0)
    dz = np.maximum(np.maximum(boxes[:, 2] - z, z - boxes[:, 3]), 0.0)
    return (np.hypot(dx, dz) < radii[:, None]).any(axis=(-1, -2))


@dataclasses.dataclass
class HeldPoses:
    """Poses held at rest: heads (n, 2) and capsule points (n, m, 2) in the base joint's frame."""
    control: np.ndarray  # (n, nu) the inputs held
    head: np.ndarray  # (n, 2)
    attitude: np.ndarray  # (n,) deg
    settled: np.ndarray  # (n,) bool
    points: np.ndarray  # (n, m, 2)
    radii: np.ndarray  # (m,)

    def level(self) -> np.ndarray:
        return self.settled & (np.abs(physics_lib.attitude_error_deg(self.attitude, LEVEL_ATTITUDE_DEG))
                               <= LEVEL_TOLERANCE_DEG)


@dataclasses.dataclass(frozen=True)
class Column:
    """A column of a scene: the poses (indices, lowest head first) and its height (m)."""
    scene: Scene | None
    poses: tuple[int, ...]
    height: float

    def summary(self, held: HeldPoses) -> dict:
        heads = held.head[list(self.poses)] if self.poses else np.zeros((0, 2))
        return {"column_height_m": round(float(self.height), 4), "poses": len(self.poses),
                "slot_x_m": None if self.scene is None else round(self.scene.slot_x, 3),
                "shelf_z_m": None if self.scene is None else round(self.scene.shelf_z, 3),
                "heads_m": [[round(float(x), 3), round(float(z), 3)] for x, z in heads]}


NO_COLUMN = Column(None, (), 0.0)


def arm_geoms(physics) -> list:
    """The arm's geoms (its links and head), base to head."""
    bodies = set(physics_lib.arm_ids(physics.model, "body").tolist())
    return [g for g in range(physics.model.ngeom) if int(physics.model.geom_bodyid[g]) in bodies]


def capsule_points(physics, geoms, to_plane) -> np.ndarray:
    """(m, 2) points along every geom's axis (``SAMPLES_PER_CAPSULE`` each), base to head, each
    world point mapped by ``to_plane`` to (forward, up)."""
    model, data = physics.model, physics.data
    points = []
    for g in geoms:
        centre, axis = data.geom_xpos[g], data.geom_xmat[g].reshape(3, 3)[:, 2]
        half = model.geom_size[g][1] if model.geom_type[g] == 3 else 0.0  # 3: capsule
        for s in np.linspace(-1.0, 1.0, SAMPLES_PER_CAPSULE):
            points.append(to_plane(centre + s * half * axis))
    return np.array(points)


def capsule_radii(physics, geoms) -> np.ndarray:
    return np.repeat(np.asarray(physics.model.geom_size)[geoms, 0], SAMPLES_PER_CAPSULE)


def slot_positions(heads_x: np.ndarray, slot_x=None) -> np.ndarray:
    """The slot centres tried for heads at ``heads_x``: every :data:`GRID` step near them, within
    ``slot_x`` = (min, max) when given (None: anywhere)."""
    grid = np.arange(np.floor((heads_x.min() - COLUMN_TOLERANCE) / GRID) * GRID,
                     heads_x.max() + COLUMN_TOLERANCE + GRID, GRID)
    if slot_x is None:
        return grid
    low, high = slot_x
    return grid[(grid >= low - 1e-9) & (grid <= high + 1e-9)]


def columns(held: HeldPoses, shelf_z: float | None = None, slot_x=None) -> list:
    """Every slot position's runs of poses in its column (module doc), tallest first, unverified;
    the shelf's underside at ``shelf_z`` (default :data:`SHELF_Z`), the slot's centre within
    ``slot_x`` = (min, max) (None: anywhere)."""
    shelf_z = SHELF_Z if shelf_z is None else shelf_z
    level = np.flatnonzero(held.level() & (held.head[:, 1] > shelf_z + scenes.GAP_SHELF_THICKNESS))
    if len(level) < 1:
        return []
    scenes_of = {}
    head = held.head[level]
    for centre in slot_positions(head[:, 0], slot_x):
        near = level[np.abs(head[:, 0] - centre) <= COLUMN_TOLERANCE]
        if not len(near):
            continue
        scene = Scene(float(centre), float(shelf_z))
        clear = near[~scene.touches(held.points[near], held.radii)]
        order = clear[np.argsort(held.head[clear, 1])]
        for run in np.split(order, np.flatnonzero(np.diff(held.head[order, 1]) > MAX_STEP) + 1):
            if len(run):
                scenes_of.setdefault(tuple(int(i) for i in run), []).append(scene)
    # One scene per run of poses, the middle of those it fits: the most room for the ramps.
    found = [Column(runs[len(runs) // 2], poses, float(held.head[poses[-1], 1] - held.head[poses[0], 1]))
             for poses, runs in scenes_of.items()]
    found.sort(key=lambda c: (-c.height, -len(c.poses)))
    return found


def tallest_column(held: HeldPoses, connected, max_ramps: int = MAX_RAMPS, slot_x=None) -> Column:
    """The tallest column (slot centre within ``slot_x``, None: anywhere) whose neighbouring poses
    are ``connected(a, b, scene)``, checking at most ``max_ramps`` pairs (a pair that fails splits
    its run, and the parts compete again)."""
    candidates = columns(held, slot_x=slot_x)
    if not candidates:
        return NO_COLUMN
    checked, best = {}, Column(candidates[0].scene, candidates[0].poses[:1], 0.0)
    while candidates:
        column = candidates.pop(0)
        if column.height <= best.height:
            break
        cut = None
        for a, b in zip(column.poses, column.poses[1:]):
            key = (a, b, column.scene)
            if key not in checked:
                if len(checked) >= max_ramps:
                    return best
                checked[key] = bool(connected(a, b, column.scene))
            if not checked[key]:
                cut = column.poses.index(b)
                break
        if cut is None:
            return column
        for part in (column.poses[:cut], column.poses[cut:]):
            height = float(held.head[part[-1], 1] - held.head[part[0], 1])
            candidates.append(Column(column.scene, part, height))
        candidates.sort(key=lambda c: (-c.height, -len(c.poses)))
    return best


def ramp_path(physics, start, end, scene: Scene, to_plane, hold_time: float, ramp_time: float = RAMP_TIME):
    """From reset hold the inputs ``start`` for ``hold_time``, ramp them to ``end`` over ``ramp_time``
    and hold :data:`RAMP_HOLD`: (clear, heads), ``heads`` (k, 2) at every control step until the
    first that touched ``scene`` (clear False) or the end."""
    geoms, boxes = arm_geoms(physics), scene.boxes()
    radii = capsule_radii(physics, geoms)
    dt = physics.model.opt.timestep
    physics.reset()
    physics.data.ctrl[:] = start
    physics.step(int(round(hold_time / dt)))
    steps, every = int(round((ramp_time + RAMP_HOLD) / dt)), 4  # 4: the environments' control step
    heads = []
    for k in range(0, steps, every):
        f = min(k * dt / ramp_time, 1.0)
        physics.data.ctrl[:] = (1 - f) * np.asarray(start) + f * np.asarray(end)
        physics.step(every)
        if physics.divergence is not None or touching(capsule_points(physics, geoms, to_plane), radii, boxes):
            return False, np.array(heads).reshape(-1, 2)
        heads.append(to_plane(physics.head_position()))
    return True, np.array(heads).reshape(-1, 2)


def ramp_stays_clear(physics, held: HeldPoses, a: int, b: int, scene: Scene, to_plane, hold_time: float) -> bool:
    """True when :func:`ramp_path` from pose ``a``'s inputs to ``b``'s keeps clear of ``scene`` and
    ends with the head within :data:`ARRIVAL` of ``b``'s."""
    clear, heads = ramp_path(physics, held.control[a], held.control[b], scene, to_plane, hold_time)
    return bool(clear and np.linalg.norm(heads[-1] - held.head[b]) <= ARRIVAL)


# --------------------------------------------------------------------------- seeking a column

# Uniform and edge kinematic samples (workspace.kinematic_samples) whose level, slot-threading
# poses propose where to seek: what the links allow, whatever the routing.
START_LIBRARY = (40_000, 40_000)
REFINE_STEP = 0.04  # m between the heads sought above and below a column found


def threading(held: HeldPoses, shelf_z: float | None = None, slot_x=None) -> np.ndarray:
    """(n,) bool: poses in the column of some slot position (within ``slot_x``), each on its own."""
    mask = np.zeros(len(held.head), bool)
    for column in columns(held, shelf_z, slot_x):
        mask[list(column.poses)] = True
    return mask


_library = {}


def over_slots(held: HeldPoses, slot_x, shelf_z: float | None = None) -> np.ndarray:
    """(n,) bool: level poses with heads above the shelf's top and over ``slot_x`` = (min, max)
    (within :data:`COLUMN_TOLERANCE`), whatever their necks touch."""
    shelf_z = SHELF_Z if shelf_z is None else shelf_z
    x = held.head[:, 0]
    return (held.level() & (held.head[:, 1] > shelf_z + scenes.GAP_SHELF_THICKNESS)
            & (x >= slot_x[0] - COLUMN_TOLERANCE) & (x <= slot_x[1] + COLUMN_TOLERANCE))


def start_library(spec, slot_x=None):
    """(heads, joint angles) of the level kinematic poses of ``spec``'s links that thread a slot
    (its centre within ``slot_x``, None: anywhere), heads in the base joint frame (computed once per
    process and range).  When none threads a slot in the range (the links' uniform and edge samples
    hold none 0.2-0.5 m ahead), the level poses with heads above the shelf over the range: the
    search still seeks there, and the way in (``design_objectives.passage_target``) has a target."""
    import mujoco
    key = (spec.joint_names, spec.link_lengths, spec.dorsal_limits_deg, spec.ventral_limits_deg, spec.head_length,
           None if slot_x is None else tuple(slot_x))
    if key not in _library:
        uniform, edge = START_LIBRARY
        samples = workspace.kinematic_samples(uniform, 0, spec, num_edge=edge)
        level = np.flatnonzero(samples.level())
        physics = scenes.frame_physics(spec)
        base, geoms = workspace.base_joint_xz(physics, spec), arm_geoms(physics)
        indices = physics_lib.arm_indices(physics.model)
        points = np.zeros((len(level), len(geoms) * SAMPLES_PER_CAPSULE, 2))
        for k, i in enumerate(level):
            physics.data.qpos[indices.qpos] = samples.joint_angles[i]
            mujoco.mj_kinematics(physics.model.ptr, physics.data.ptr)
            points[k] = capsule_points(physics, geoms, lambda p: np.asarray(p)[[0, 2]] - base)
        held = HeldPoses(np.zeros((len(level), 0)), samples.head_position[level] - base, samples.head_attitude[level],
                         np.ones(len(level), bool), points, capsule_radii(physics, geoms))
        keep = threading(held, slot_x=slot_x)
        if slot_x is not None and not keep.any():
            keep = over_slots(held, slot_x)
        _library[key] = (held.head[keep], samples.joint_angles[level][keep])
    return _library[key]


def hold_poses(physics, controls, to_plane, hold_time: float, interrupted=lambda: False) -> HeldPoses:
    """Hold each of ``controls`` from reset for ``hold_time`` s and record the pose."""
    geoms = arm_geoms(physics)
    n, m = len(controls), len(geoms) * SAMPLES_PER_CAPSULE
    held = HeldPoses(np.array(controls, float).reshape(n, physics.model.nu), np.zeros((n, 2)), np.zeros(n),
                     np.zeros(n, bool), np.zeros((n, m, 2)), capsule_radii(physics, geoms))
    for i, control in enumerate(held.control):
        if interrupted():
            raise KeyboardInterrupt
        held.settled[i] = workspace.settle(physics, control, hold_time)
        held.head[i] = to_plane(physics.head_position())
        held.attitude[i] = physics.head_attitude()
        held.points[i] = capsule_points(physics, geoms, to_plane)
    return held


def spread(heads: np.ndarray, count: int) -> np.ndarray:
    """Indices of ``count`` of ``heads`` spread out: farthest-point order from the highest head."""
    if len(heads) == 0:
        return np.zeros(0, int)
    chosen = [int(np.argmax(heads[:, 1]))]
    distance = np.linalg.norm(heads - heads[chosen[0]], axis=1)
    while len(chosen) < min(count, len(heads)):
        chosen.append(int(np.argmax(distance)))
        distance = np.minimum(distance, np.linalg.norm(heads - heads[chosen[-1]], axis=1))
    return np.array(chosen)


def refine_targets(held: HeldPoses, count: int, slot_x=None):
    """Targets that would grow the tallest column of ``held`` (slot within ``slot_x``): heads sought
    above and below it at its x, alternately; None without a column."""
    found = columns(held, slot_x=slot_x)
    if not found:
        return None
    heads = held.head[list(found[0].poses)]
    x, low, high = float(heads[:, 0].mean()), float(heads[:, 1].min()), float(heads[:, 1].max())
    steps = [(high + REFINE_STEP * (k // 2 + 1)) if k % 2 == 0 else (low - REFINE_STEP * (k // 2 + 1))
             for k in range(count)]
    return np.array([[x, z] for z in steps], float).reshape(-1, 2)


def measure(spec, layout, coarse_count: int, refine_count: int, seek_time: float, hold_time: float,
            max_ramps: int = MAX_RAMPS, interrupted=lambda: False, slot_x=None) -> tuple[Column, HeldPoses]:
    """The tallest column (module doc; the slot's centre within ``slot_x``, None: anywhere) among
    poses sought at ``coarse_count`` spread heads of :func:`start_library` (each from its own
    kinematic pose's tendon lengths), then at ``refine_count`` more that would grow the tallest
    column found (:func:`refine_targets`; without one, at further library heads); the poses too."""
    physics = scenes.frame_physics(spec, layout)
    base = workspace.base_joint_xz(physics, spec)

    def to_plane(point):
        return np.asarray(point)[[0, 2]] - base

    heads, angles = start_library(spec, slot_x)
    order = spread(heads, coarse_count + refine_count)

    def seek(targets, starts):
        controls = []
        for target, start in zip(targets, starts):
            if interrupted():
                raise KeyboardInterrupt
            controls.append(pose_seek.seek_pose(physics, target + base,
                                                pose_seek.contraction_at(physics, start, spec), seek_time))
        return controls

    first = order[:coarse_count]
    held = hold_poses(physics, seek(heads[first], angles[first]), to_plane, hold_time, interrupted)
    if refine_count:
        targets = refine_targets(held, refine_count, slot_x)
        if targets is None:
            rest = order[coarse_count:]
            targets, starts = heads[rest], angles[rest]
        else:
            starts = [angles[np.argmin(np.linalg.norm(heads - t, axis=1))] for t in targets]
        more = hold_poses(physics, seek(targets, starts), to_plane, hold_time, interrupted)
        held = HeldPoses(*(np.concatenate([getattr(held, f), getattr(more, f)])
                           for f in ("control", "head", "attitude", "settled", "points")), held.radii)

    def connected(a, b, scene):
        if interrupted():
            raise KeyboardInterrupt
        return ramp_stays_clear(physics, held, a, b, scene, to_plane, hold_time)

    return tallest_column(held, connected, max_ramps, slot_x), held
