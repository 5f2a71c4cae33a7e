"""What Table 1's links allow at the narrow gap, whatever the routing: a bound no routing can beat.

    python -m robostrich_suite.studies.gap_bound --out docs          # docs/gap_bound.png and .json

A routing only decides which poses the arm can hold; the links and their joint limits decide
which poses exist.  This measures, purely kinematically (joint angles within the model's joint
ranges, ``mj_kinematics`` on the arm on its frame, no tendons, no gravity), whether a pose exists
with the head level (within the tasks' 5 deg) over a slot 7 cm wide (the head within
``gap_column.COLUMN_TOLERANCE`` of its centre in x), above the task's shelf, and no capsule of the
arm touching the shelf, the wall above it or the ground: the neck then crosses the shelf's plane
inside the slot.  The scene is :class:`gap_column.Scene`, the geometry ``gap_column``'s capsule
points, so "in the column" means here what it means to the gap measure.

Random joint angles almost never thread a slot (the 80,000 uniform and edge samples of
``gap_column.start_library`` hold none 0.2-0.5 m ahead), so poses are *sought*: from many random
starts, ``scipy.optimize.least_squares`` over the 18 joint angles (bounded by the joint ranges)
drives residuals to zero: the head at the slot's x and a height, the attitude within the
tolerance, every capsule point its radius plus :data:`MARGIN` clear of every box.  Where a pose is
found, the height is stepped up and down by :data:`Z_STEP` from it (each step started from the last
pose), so a column's height is the range of heads found without a gap of more than one step.

What it ignores makes it a bound: the links' contacts with each other, gravity and tendons, and
whether neighbouring poses can be joined; a column here is necessary for a routing's column,
not sufficient.  What it cannot prove: a search that finds no pose is evidence, not proof, that
none exists (the starts are many and spread, the residuals smooth; :data:`STARTS`).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import pathlib

import numpy as np

from robostrich_suite import scenes
from robostrich_suite.tasks.conventions import LEVEL_ATTITUDE_DEG, LEVEL_TOLERANCE_DEG
from robostrich_suite.studies import gap_column
from robostrich_suite import cli as cli_lib
from robostrich_suite import physics as physics_lib
from robostrich_suite.atomic_files import save_figure, write_text
from robostrich_suite.studies import workspace

MARGIN = 0.002  # m a sought pose keeps its capsules clear of the scene (checked at 0: gap_column.touching)
ATTITUDE_AIM = LEVEL_TOLERANCE_DEG - 1.0  # deg: sought inside the tolerance, checked at it
Z_STEP = 0.01  # m between the heights of a column
X_STEP = 0.005  # m the slot is moved forward from a column, each pose sought from the last
MISS_STARTS = 16  # starts sought with the scene ignored, for the nearest miss of the slot
MAX_STEPS = 60  # column heights stepped above and below a pose found: 0.6 m, more than the links reach
PUSHED_SEEDS = 8  # poses of the farthest slot with a column pushed forward from
STARTS = 48  # random starts per slot position
TASK_STARTS = 1000  # random starts at the task's slot itself, the question that matters most
SLOTS = tuple(np.round(np.arange(0.20, 0.501, 0.02), 3))  # m: slot centres tried, the task's range
SEED = 0


@dataclasses.dataclass
class Pose:
    joint_angles: np.ndarray
    head: np.ndarray  # (2,) base joint frame
    attitude: float  # deg, wrapped to (-180, 180]
    points: np.ndarray  # (m, 2)


class Arm:
    """The arm's kinematics on its frame: joint angles -> head, attitude and capsule points in the
    base joint's (forward, up) plane."""

    def __init__(self, spec=None):
        import mujoco
        physics = scenes.frame_physics(spec)
        self._mujoco, self.model, self.data = mujoco, physics.model.ptr, physics.data.ptr
        indices = physics_lib.arm_indices(physics.model)
        self.qpos, self.head_site, self.head_body = indices.qpos, indices.head_site, indices.head_body
        self.low, self.high = (np.asarray(physics.model.jnt_range)[indices.joints].T).copy()
        self.base = workspace.base_joint_xz(physics, spec)
        self.geoms = np.array(gap_column.arm_geoms(physics))
        self.radii = gap_column.capsule_radii(physics, list(self.geoms))
        sizes = np.asarray(physics.model.geom_size)[self.geoms]
        half = np.where(np.asarray(physics.model.geom_type)[self.geoms] == 3, sizes[:, 1], 0.0)
        self._offsets = half[:, None] * np.linspace(-1.0, 1.0, gap_column.SAMPLES_PER_CAPSULE)[None, :]

    def pose(self, joint_angles) -> Pose:
        self.data.qpos[self.qpos] = joint_angles
        self._mujoco.mj_kinematics(self.model, self.data)
        centre = self.data.geom_xpos[self.geoms][:, [0, 2]]
        axis = self.data.geom_xmat[self.geoms][:, [2, 8]]  # the geoms' z axes, (x, z)
        points = (centre[:, None, :] + self._offsets[..., None] * axis[:, None, :]).reshape(-1, 2) - self.base
        xmat = self.data.xmat[self.head_body]
        attitude = math.degrees(math.atan2(xmat[2], xmat[8]))
        return Pose(np.array(joint_angles, float), self.data.site_xpos[self.head_site][[0, 2]] - self.base,
                    attitude, points)

    def random_angles(self, rng, count: int) -> np.ndarray:
        return rng.uniform(self.low, self.high, size=(count, len(self.low)))


def attitude_error(attitude: float) -> float:
    return (attitude - LEVEL_ATTITUDE_DEG + 180.0) % 360.0 - 180.0


def signed_distance(points: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """(m, b) distance of each point outside each box [x0, x1, z0, z1] (negative: its depth inside)."""
    x, z = points[:, 0, None], points[:, 1, None]
    dx = np.maximum(boxes[:, 0] - x, x - boxes[:, 1])
    dz = np.maximum(boxes[:, 2] - z, z - boxes[:, 3])
    outside = np.hypot(np.maximum(dx, 0.0), np.maximum(dz, 0.0))
    return np.where((dx > 0) | (dz > 0), outside, np.maximum(dx, dz))


def in_column(pose: Pose, scene: gap_column.Scene, radii: np.ndarray) -> bool:
    """The gap measure's test of one pose (module doc), with nothing held: level, head over the slot
    above the shelf, nothing touching."""
    top = scene.shelf_z + scenes.GAP_SHELF_THICKNESS
    return bool(abs(attitude_error(pose.attitude)) <= LEVEL_TOLERANCE_DEG
                and abs(pose.head[0] - scene.slot_x) <= gap_column.COLUMN_TOLERANCE and pose.head[1] > top
                and not gap_column.touching(pose.points[None], radii, scene.boxes())[0])


def miss(pose: Pose, scene: gap_column.Scene, radii: np.ndarray) -> float:
    """How far (m) the neck misses the slot where it crosses the shelf's band (0: through it), for a
    pose whose head is level over the slot above the shelf; infinite otherwise.  The nearest a
    sought pose came to the column."""
    top = scene.shelf_z + scenes.GAP_SHELF_THICKNESS
    if (abs(attitude_error(pose.attitude)) > LEVEL_TOLERANCE_DEG or pose.head[1] <= top
            or abs(pose.head[0] - scene.slot_x) > gap_column.COLUMN_TOLERANCE):
        return math.inf
    x, z = pose.points[:, 0], pose.points[:, 1]
    band = (z + radii > scene.shelf_z) & (z - radii < top)
    if not band.any():
        return math.inf
    return float(np.maximum(np.abs(x[band] - scene.slot_x) + radii[band] - scenes.GAP_SLOT_WIDTH / 2, 0.0).max())


def seek(arm: Arm, scene: gap_column.Scene, start: np.ndarray, height: float | None, clear: bool = True) -> Pose:
    """The pose least_squares reaches from ``start``: the head level at the slot's x and at ``height``
    (None: anywhere above the shelf's top plus the head's radius), every capsule clear (with ``clear``;
    without, the scene is ignored but for the head's height)."""
    from scipy.optimize import least_squares
    boxes = scene.boxes()
    lowest = scene.shelf_z + scenes.GAP_SHELF_THICKNESS + arm.radii[-1] + MARGIN

    def residuals(q):
        pose = arm.pose(q)
        x, z = pose.head
        height_error = (z - height) if height is not None else min(z - lowest, 0.0)
        attitude = max(abs(attitude_error(pose.attitude)) - ATTITUDE_AIM, 0.0)
        overlap = np.maximum(arm.radii[:, None] + MARGIN - signed_distance(pose.points, boxes), 0.0) if clear else []
        return np.concatenate([[(x - scene.slot_x) / 0.005, height_error / 0.005, attitude / 1.0],
                               np.ravel(overlap) / 0.002])

    start = np.clip(start, arm.low + 1e-6, arm.high - 1e-6)
    result = least_squares(residuals, start, bounds=(arm.low, arm.high), method="trf", max_nfev=60, x_scale=0.1)
    return arm.pose(result.x)


def climb(arm: Arm, scene: gap_column.Scene, pose: Pose, step: float, limit: int) -> list:
    """Poses in the column from ``pose`` on, its head stepped by ``step`` each (until one is not found)."""
    found = []
    for _ in range(limit):
        nxt = seek(arm, scene, pose.joint_angles, float(pose.head[1] + step))
        if not in_column(nxt, scene, arm.radii) or abs(nxt.head[1] - pose.head[1] - step) > Z_STEP / 2:
            break
        found.append(pose := nxt)
    return found


def column_at(arm: Arm, slot_x: float, shelf_z: float, starts: np.ndarray, steps: int = MAX_STEPS) -> dict:
    """The tallest column of poses found at a slot centred at ``slot_x`` (base joint frame, m; at most
    ``steps`` above and below a pose found): its height, its poses lowest first, how many starts
    found a pose at all, and the nearest miss of the slot (:func:`miss`)."""
    scene = gap_column.Scene(float(slot_x), float(shelf_z))
    sought = [seek(arm, scene, q, None) for q in starts]
    seeds = [p for p in sought if in_column(p, scene, arm.radii)]
    best = []
    for seed in seeds:
        if best and best[0].head[1] - 1e-9 <= seed.head[1] <= best[-1].head[1] + 1e-9:
            continue  # inside a column found already
        column = climb(arm, scene, seed, -Z_STEP, steps)[::-1] + [seed] + climb(arm, scene, seed, Z_STEP, steps)
        if column[-1].head[1] - column[0].head[1] >= (best[-1].head[1] - best[0].head[1] if best else -1.0):
            best = column
    free = [seek(arm, scene, q, None, clear=False) for q in starts[:MISS_STARTS]] if not seeds else []
    nearest = min(sought + free, key=lambda p: miss(p, scene, arm.radii))
    return {"slot_x_m": float(slot_x), "shelf_z_m": float(shelf_z), "seeds_found": len(seeds), "starts": len(starts),
            "seeds": seeds,
            "least_miss_m": _finite(miss(nearest, scene, arm.radii)), "nearest": nearest,
            "column_height_m": round(float(best[-1].head[1] - best[0].head[1]), 4) if best else None,
            "heads_z_m": [round(float(best[0].head[1]), 4), round(float(best[-1].head[1]), 4)] if best else None,
            "poses": best}


def _finite(value: float):
    return round(value, 4) if math.isfinite(value) else None


def push_forward(arm: Arm, shelf_z: float, seeds: list, step: float = X_STEP, limit: int = 80):
    """The farthest slot centre (m) a pose in the column reaches when the slot is moved forward by
    ``step`` at a time from each of ``seeds`` ((slot_x, pose) pairs; each pose sought from the last,
    at any height), and that pose: the columns' edge approached from where they exist."""
    best_x, best = -math.inf, None
    for slot_x, pose in seeds:
        x = slot_x
        for _ in range(limit):
            scene = gap_column.Scene(float(x + step), float(shelf_z))
            nxt = seek(arm, scene, pose.joint_angles, None)
            if not in_column(nxt, scene, arm.radii):
                break
            x, pose = x + step, nxt
        if x > best_x:
            best_x, best = x, pose
    return round(float(best_x), 4), best


def forward_curl(arm: Arm, shelf_z: float) -> dict:
    """Every joint bent forward (ventral) to its limit: where the neck passes the shelf's underside
    height and where it is highest, the farthest forward a neck can be low (m, base joint frame)."""
    points = arm.pose(arm.high).points
    rising = points[: int(np.argmax(points[:, 1])) + 1]
    crossing = rising[int(np.argmax(rising[:, 1] >= shelf_z))]
    top = points[int(np.argmax(points[:, 1]))]
    return {"passes_shelf_height_at_x_m": round(float(crossing[0]), 4),
            "highest_point_m": [round(float(v), 4) for v in top]}


def survey(slots, shelves, starts: int = STARTS, seed: int = SEED, spec=None, progress=None,
           steps: int = MAX_STEPS, pushed: int = PUSHED_SEEDS, task_starts: int = TASK_STARTS) -> dict:
    """:func:`column_at` at every slot centre of ``slots`` under the task's shelf, then the slot pushed
    forward from ``pushed`` poses of the farthest columns (:func:`push_forward`), the task's slot
    under every shelf height of ``shelves`` (m above the base joint): what a scene change buys; last
    the task's slot and shelf from ``task_starts`` starts (0: none)."""
    arm, rng = Arm(spec), np.random.default_rng(seed)
    progress = progress or (lambda: None)
    rows = {"slots": [], "shelves": [], "forward_curl": forward_curl(arm, gap_column.SHELF_Z)}
    for x in slots:
        rows["slots"].append(column_at(arm, x, gap_column.SHELF_Z, arm.random_angles(rng, starts), steps))
        progress()
    seeds = sorted(((r["slot_x_m"], p) for r in rows["slots"] for p in r["seeds"]), key=lambda s: -s[0])
    if seeds:
        rows["pushed_x_m"], rows["pushed_pose"] = push_forward(arm, gap_column.SHELF_Z, seeds[:pushed])
    for z in shelves:
        rows["shelves"].append(column_at(arm, gap_column.TASK_NEED["slot_x_m"], z, arm.random_angles(rng, starts),
                                         steps))
        progress()
    if task_starts:
        rows["task"] = column_at(arm, gap_column.TASK_NEED["slot_x_m"], gap_column.SHELF_Z,
                                 arm.random_angles(rng, task_starts), steps)
    return rows


def task_row(rows: dict) -> dict:
    """The task's slot under its shelf: its own many-start row, else the nearest slot of the survey."""
    x = gap_column.TASK_NEED["slot_x_m"]
    return rows.get("task") or min(rows["slots"], key=lambda r: abs(r["slot_x_m"] - x))


def summary(rows: dict, command: str) -> dict:
    """The survey as JSON: per slot and shelf, the column found (no poses), and the task's verdict."""
    def strip(row):
        return {k: v for k, v in row.items() if k not in ("poses", "nearest", "seeds")}
    need = gap_column.TASK_NEED
    task = task_row(rows)
    forward = [r for r in rows["slots"] if (r["column_height_m"] or 0.0) >= need["column_height_m"]]
    in_range = [r for r in rows["slots"] if 0.2 - 1e-9 <= r["slot_x_m"] <= 0.5 + 1e-9]
    return {"command": command, "need": need, "starts_per_slot": rows["slots"][0]["starts"],
            "task_slot": strip(task),
            "best_in_task_range_m": max((r["column_height_m"] or 0.0) for r in in_range) if in_range else None,
            "farthest_slot_with_needed_column_m": max((r["slot_x_m"] for r in forward), default=None),
            "farthest_slot_pushed_m": rows.get("pushed_x_m"), "forward_curl": rows["forward_curl"],
            "slots": [strip(r) for r in rows["slots"]], "shelves": [strip(r) for r in rows["shelves"]]}


def _draw_scene(ax, scene: gap_column.Scene) -> None:
    from matplotlib.patches import Rectangle
    for x0, x1, z0, z1 in scene.boxes()[:3]:
        ax.add_patch(Rectangle((x0, z0), x1 - x0, min(z1, 1.0) - z0, color="0.55"))
    ax.axhline(scene.boxes()[3, 3], color="0.3", lw=2)


def _draw_pose(ax, pose: Pose, color, label=None) -> None:
    ax.plot(pose.points[:, 0], pose.points[:, 1], color=color, lw=2.5, solid_capstyle="round", label=label)
    ax.plot(*pose.head, "*", color="k", ms=7)


def plot(rows: dict, result: dict, path) -> None:
    """Column height per slot centre (left), the farthest column forward with its poses (middle), and the
    task's slot with the nearest poses found (right), the need written on it."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    need = gap_column.TASK_NEED
    fig, axes = plt.subplots(1, 3, figsize=(17, 5.6), gridspec_kw={"width_ratios": [1.2, 1, 1]})
    ax = axes[0]
    x = [r["slot_x_m"] for r in rows["slots"]]
    ax.bar(x, [100 * (r["column_height_m"] or 0.0) for r in rows["slots"]], width=0.015, color="C0",
           label="tallest column of level poses found")
    ax.axvspan(0.2, 0.5, color="C1", alpha=0.12, label="the searches' slot range (0.2-0.5 m)")
    ax.plot(need["slot_x_m"], 100 * need["column_height_m"], "rX", ms=12, label="the task's slot and need")
    if result.get("farthest_slot_pushed_m") is not None:
        ax.axvline(result["farthest_slot_pushed_m"], color="k", ls="--", lw=1,
                   label=f"farthest slot reached moving it forward: {result['farthest_slot_pushed_m']:.3f} m")
    task = result["task_slot"]
    verdict = (f"none found ({task['starts']} starts)" if task["column_height_m"] is None
               else f"{100 * task['column_height_m']:.1f} cm")
    ax.set_title(f"Table 1's links, any routing: column at the task's slot ({need['slot_x_m']} m): {verdict}; "
                 f"needs {100 * need['column_height_m']:.0f} cm", fontsize=9)
    ax.set_xlabel("slot centre, ahead of the base joint (m)")
    ax.set_ylabel("column height (cm)")
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(True, alpha=0.3)
    edge = [r for r in rows["slots"] if r["poses"]]
    if edge:
        row = max(edge, key=lambda r: r["slot_x_m"])
        scene = gap_column.Scene(row["slot_x_m"], row["shelf_z_m"])
        _draw_scene(axes[1], scene)
        for pose, color in zip((row["poses"][0], row["poses"][-1]), ("C0", "C2")):
            _draw_pose(axes[1], pose, color, f"head {pose.head[1]:.3f} m up")
        axes[1].set_title(f"the farthest slot forward with a column: {row['slot_x_m']:.2f} m, "
                          f"{100 * row['column_height_m']:.1f} cm (lowest, highest pose)", fontsize=9)
    task = task_row(rows)
    _draw_scene(axes[2], gap_column.Scene(task["slot_x_m"], task["shelf_z_m"]))
    _draw_pose(axes[2], task["nearest"], "C3", "nearest pose found: head level over the slot")
    axes[2].plot([need["slot_x_m"]] * 2, need["heads_z_m"], "rX", ms=9, ls="", label="the task's sub-targets 5 and 6")
    miss_text = "" if task["least_miss_m"] is None else f"; the neck {100 * task['least_miss_m']:.0f} cm off it"
    found = "none threads it" if not task["seeds_found"] else f"{task['seeds_found']} thread it"
    axes[2].set_title(f"task's slot {task['slot_x_m']:.2f} m, {task['starts']} starts: {found}{miss_text}", fontsize=9)
    for ax in axes[1:]:
        ax.plot(0, 0, "ks", ms=6)
        ax.set_xlim(-0.25, 0.65)
        ax.set_ylim(-0.1, 0.7)
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.3)
        ax.set_xlabel("forward of the base joint (m)")
        ax.legend(fontsize=8, loc="lower right")
    axes[1].set_ylabel("above the base joint (m; the shelf grey)")
    fig.tight_layout()
    save_figure(fig, path, dpi=80)
    plt.close(fig)


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(prog="python -m robostrich_suite.studies.gap_bound",
                                     description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--starts", type=cli_lib.whole_number(1, 10_000), default=STARTS,
                        help="random starts per slot position (default: %(default)s)")
    parser.add_argument("--task-starts", type=cli_lib.whole_number(0, 100_000), default=TASK_STARTS,
                        help="random starts at the task's slot itself (default: %(default)s)")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("docs"),
                        help="directory for gap_bound.png and gap_bound.json (default: %(default)s)")
    args = parser.parse_args(argv)
    from tqdm import tqdm
    slots = np.round(np.arange(-0.10, 0.501, 0.02), 3)
    shelves = np.round(np.arange(gap_column.SHELF_Z, 0.40, 0.05), 3)
    with tqdm(total=len(slots) + len(shelves), desc="slots", unit="slot") as bar:
        rows = survey(slots, shelves, args.starts, progress=bar.update, task_starts=args.task_starts)
    command = " ".join(["python -m robostrich_suite.studies.gap_bound", *(argv or [])])
    result = summary(rows, command)
    args.out.mkdir(parents=True, exist_ok=True)
    write_text(args.out / "gap_bound.json", json.dumps(result, indent=1) + "\n")
    plot(rows, result, args.out / "gap_bound.png")
    print(json.dumps({k: result[k] for k in ("task_slot", "best_in_task_range_m", "farthest_slot_with_needed_column_m",
                                            "farthest_slot_pushed_m")}, indent=1))
    return result


if __name__ == "__main__":
    main()
