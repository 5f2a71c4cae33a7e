"""Where a narrow gap can be for a layout: the level poses the arm holds on the standing quadruped.

    python tools/gap_kinematics.py [--layout ventral_slips] [--transitions 12] [--out docs/gap]

A narrow gap passed vertically (Sec. 5.2.2, Fig. 10) needs level poses with the head at one x
below and above a barrier, and a neck that threads the barrier's slot in all of them: the neck
must reach the head from below, through the slot.  This holds every stored input of the
layout's lookup table on the standing quadruped (as the task's stored starts do), sorts the
level poses into families, and measures what decides it:

* the families: curled (a full backward turn, head low behind the mount), forward (head ahead of
  the trunk) and raised (head above the trunk);
* the pivot: how far along the neck the forward family's poses agree (within 2 cm): beyond it
  the distal neck swings as a lever while the head moves up and down, sweeping every barrier
  between the pivot and the head;
* the crossings: from curled poses (the only ones under a barrier over the mount) to raised ones
  (a neck rising through a slot over the mount), the input ramped over 1 s, how far behind the
  mount the neck passes the barrier's height.

Writes OUT/gap_kinematics.png (the families, the pivot, the crossings) and OUT/gap_kinematics.json.
The neck's geometry is robostrich_suite/studies/gap_column.py's, which robostrich-design's gap measure
(the tallest column of level poses through a slot, for any routing) is built on.
"""
import argparse
import json
import os

import numpy as np

from robostrich_suite.studies.gap_column import SAMPLES_PER_CAPSULE  # points per capsule
from robostrich_suite import targets
from robostrich_suite.atomic_files import save_figure, write_text
from robostrich_suite.model import layouts
from robostrich_suite.studies import gap_column
from robostrich_suite.tasks.starts import STORED_START_SETTLE_TIME, hold_before_episode
import robostrich_suite

LEVEL_TOLERANCE = 5.0  # deg, as the tasks' attitude tolerance
AGREEMENT = 0.02  # m: poses "agree" up to the last neck point where 95 % of them lie within this of their mean
BARRIER_BAND = (0.48, 0.51)  # m above ground: just over the curled poses' highest point


def capsule_points(physics, geoms) -> np.ndarray:
    """(n, 2) (forward, up) points along every arm geom's axis, base to head, in the trunk frame."""
    return gap_column.capsule_points(physics, geoms, lambda point: physics.to_trunk_frame(point)[[0, 2]])


def hold_all(env, controls):
    """Head (forward, up), unwrapped attitude and neck points of every input held for 2 s."""
    physics = env.physics
    geoms = gap_column.arm_geoms(physics)
    head, attitude, neck = [], [], []
    for inputs in controls:
        env.reset()
        hold_before_episode(physics, inputs, STORED_START_SETTLE_TIME)
        head.append(physics.to_trunk_frame(physics.head_position())[[0, 2]])
        attitude.append(physics.head_attitude())
        neck.append(capsule_points(physics, geoms))
    return np.array(head), np.array(attitude), np.array(neck), geoms


def families(head, attitude) -> dict:
    """Boolean masks of the level poses by family (module doc)."""
    off_level = (attitude - 90.0 + 180.0) % 360.0 - 180.0
    level = np.abs(off_level) <= LEVEL_TOLERANCE
    curled = level & (attitude < -180.0)
    forward = level & ~curled & (head[:, 0] > 0.4) & (head[:, 1] < 0.75)
    return {"curled": curled, "forward": forward, "raised": level & ~curled & ~forward}


def pivot(neck, mask):
    """The last neck point where 95 % of the poses of `mask` lie within AGREEMENT of their mean."""
    spread = np.percentile(np.linalg.norm(neck[mask] - neck[mask].mean(0), axis=-1), 95, axis=0)
    index = int(np.argmax(spread > AGREEMENT)) - 1 if (spread > AGREEMENT).any() else len(spread) - 1
    return max(index, 0), neck[mask].mean(0)[max(index, 0)]


def swept_heights(neck, mask, forward: float) -> list:
    """Lowest and highest point at which the poses of `mask` cross the vertical line at `forward`."""
    heights = []
    for points in neck[mask]:
        crossing = np.flatnonzero(np.diff(np.sign(points[:, 0] - forward)) != 0)
        for k in crossing:
            (x0, z0), (x1, z1) = points[k], points[k + 1]
            heights.append(float(z0 + (forward - x0) / (x1 - x0) * (z1 - z0)))
    return [round(min(heights), 3), round(max(heights), 3)] if heights else None


def crossings(env, controls, start, goal, count, seed=0):
    """Ramp from curled to raised inputs over 1 s; per transition the rearmost x at which any
    neck point lies in BARRIER_BAND, and the rearmost of the goal pose itself."""
    physics = env.physics
    geoms = gap_column.arm_geoms(physics)
    rng = np.random.default_rng(seed)
    steps = int(round(env.control_timestep() / physics.timestep()))
    rows = []
    for _ in range(count):
        i, j = int(rng.choice(start)), int(rng.choice(goal))
        env.reset()
        hold_before_episode(physics, controls[i], STORED_START_SETTLE_TIME)
        rearmost, path = np.inf, []
        for k in range(int(round(2.0 / env.control_timestep()))):
            f = min(k * env.control_timestep() / 1.0, 1.0)
            physics.set_arm_control((1 - f) * controls[i] + f * controls[j])
            physics.step(steps)
            points = capsule_points(physics, geoms)
            band = (points[:, 1] >= BARRIER_BAND[0]) & (points[:, 1] <= BARRIER_BAND[1])
            if band.any():
                rearmost = min(rearmost, float(points[band, 0].min()))
            path.append(points[-1])
        rows.append({"from": i, "to": j, "rearmost_x_in_band": rearmost, "head_path": np.array(path)})
    return rows


def plot(head, neck, masks, pivot_point, rows, mount, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 4, figsize=(20, 5.5), sharex=True, sharey=True)
    rng = np.random.default_rng(0)
    for ax, (name, mask) in zip(axes, masks.items()):
        chosen = np.flatnonzero(mask)
        for i in rng.choice(chosen, min(20, chosen.size), replace=False) if chosen.size else []:
            ax.plot(neck[i, :, 0], neck[i, :, 1], lw=0.8)
            ax.plot(*head[i], "k*", ms=5)
        ax.set_title(f"{name}: {mask.sum()} level poses ({min(20, mask.sum())} drawn)")
    axes[1].plot(*pivot_point, "ro", ms=9, mfc="none", mew=2, label="pivot (poses agree to here)")
    ax = axes[3]
    for row in rows:
        ax.plot(row["head_path"][:, 0], row["head_path"][:, 1], lw=0.8)
    ax.axhspan(*BARRIER_BAND, color="0.6", alpha=0.5, label="barrier height over the mount")
    ax.set_title("head paths: curled -> a raised pose's input (1 s ramp)")
    for ax in axes:
        ax.plot(*mount, "ks", ms=6)
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.3)
        ax.set_xlabel("forward of the trunk centre (m)")
    axes[0].set_ylabel("above ground (m)")
    axes[0].set_xlim(-0.6, 0.8)
    axes[0].set_ylim(0.1, 1.0)
    key = [plt.Line2D([], [], color="C0", lw=0.8, label="a level pose's neck (one colour each)"),
           plt.Line2D([], [], color="k", marker="*", ls="", label="its head"),
           plt.Line2D([], [], color="k", marker="s", ls="", label="the arm's mount on the trunk"),
           *axes[1].get_legend_handles_labels()[0], *axes[3].get_legend_handles_labels()[0],
           plt.Line2D([], [], color="C1", lw=0.8, label="a head path (right)")]
    fig.legend(handles=key, loc="lower center", ncol=len(key), fontsize=9, frameon=False)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    save_figure(fig, path, dpi=80)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    p.add_argument("--layout", default=None, help="built-in tendon layout (default: the suite's)")
    p.add_argument("--transitions", type=int, default=12, help="curled -> raised ramps to simulate (1-200)")
    p.add_argument("--out", default="docs", help="directory for gap_kinematics.png and .json")
    args = p.parse_args(argv)
    if not 1 <= args.transitions <= 200:
        p.error(f"--transitions must be 1-200, got {args.transitions}")
    layout = args.layout or layouts.DEFAULT
    kwargs = {} if layout == layouts.DEFAULT else layouts.task_kwargs(layout)
    env = robostrich_suite.load("robostrich_a1", "lesson2", task_kwargs=kwargs)
    controls = targets.level_head_poses(layouts.target_file(layout))["control"]
    head, attitude, neck, _ = hold_all(env, controls)
    masks = families(head, attitude)
    index, pivot_point = pivot(neck, masks["forward"]) if masks["forward"].any() else (0, neck[0, 0])
    env.reset()
    mount = env.physics.to_trunk_frame(env.physics.arm_base_position())[[0, 2]]
    rows = crossings(env, controls, np.flatnonzero(masks["curled"]), np.flatnonzero(masks["raised"]),
                     args.transitions) if masks["curled"].any() and masks["raised"].any() else []
    summary = {
        "layout": layout, "stored_inputs": len(controls),
        "families": {name: {"poses": int(m.sum()),
                            "head_forward_m": [round(float(head[m, 0].min()), 3), round(float(head[m, 0].max()), 3)] if m.any() else None,
                            "head_up_m": [round(float(head[m, 1].min()), 3), round(float(head[m, 1].max()), 3)] if m.any() else None,
                            "highest_point_m": round(float(neck[m, :, 1].max()), 3) if m.any() else None}
                     for name, m in masks.items()},
        "forward_pivot": {"neck_point": index, "of": int(neck.shape[1]),
                          "forward_m": round(float(pivot_point[0]), 3), "up_m": round(float(pivot_point[1]), 3)},
        "forward_swept_up_m": {f"{x:.2f}": swept_heights(neck, masks["forward"], x)
                               for x in np.round(np.linspace(float(pivot_point[0]) + 0.05, 0.45, 4), 2)},
        "mount": [round(float(v), 3) for v in mount],
        "barrier_band_m": list(BARRIER_BAND),
        "curled_to_raised": [{"from": r["from"], "to": r["to"],
                              "rearmost_x_in_band_m": round(r["rearmost_x_in_band"], 3)} for r in rows],
    }
    os.makedirs(args.out, exist_ok=True)
    write_text(os.path.join(args.out, "gap_kinematics.json"), json.dumps(summary, indent=1) + "\n")
    plot(head, neck, masks, pivot_point, rows, mount, os.path.join(args.out, "gap_kinematics.png"))
    print(json.dumps({k: summary[k] for k in ("layout", "families", "forward_pivot", "forward_swept_up_m", "mount")}, indent=1))
    if rows:
        x = [r["rearmost_x_in_band"] for r in rows]
        print(f"curled -> raised: the neck crosses {BARRIER_BAND} m as far back as "
              f"{min(x):.2f} to {max(x):.2f} m (mount at {mount[0]:.2f} m)")


if __name__ == "__main__":
    main()
