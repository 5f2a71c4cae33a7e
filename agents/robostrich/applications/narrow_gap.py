"""The reaching task through a narrow gap (Sec. 5.2.2, Figs. 10-12): rollouts and metrics.

`robostrich_a1/narrow_gap`: the quadruped walks up to a wall and stops; the head tracks six
sub-targets fixed in the world, under the wall's shelf, up through its 7 cm slot, to target 6
on top.  When the next sub-target becomes active is the task's `switch` option: `"time"`
(the default: every `steps_per_target` control steps, 1.2 s, the same schedule for every
policy, as `track` and the paper's Fig. 12) or `"reached"` (once the head is within the
position tolerance of the current one).  Under the time schedule sub-targets 1-3 are active
while the quadruped still walks, farther ahead of the arm than the head reaches, so only
`"reached"` tests whether a policy can follow the whole sequence.

Per sub-target the report says whether the head came within the task's position tolerance
(0.05 m) while it was active, how long that took, and the largest contact force between any
arm geom and the obstacle (wall, shelf, posts: the scene's `gap_*` geoms), from MuJoCo's
`mj_contactForce` (norm of the normal and friction force, N).  A seed succeeds when the head
reached target 6 and the head itself (the atlas link) never touched the obstacle.
"""
import os
from typing import Optional

import mujoco
import numpy as np

from agents.robostrich.applications import rollouts as applications
from robostrich_suite import scenes
from robostrich_suite.physics import arm_ids, arm_indices

TASK = "narrow_gap"
OBSTACLE_PREFIX = "gap_"


class ContactProbe:
    """The obstacle's geoms, the arm's and the head's in one compiled model, and the largest
    contact forces between them at the current state."""

    def __init__(self, physics):
        model = physics.model
        self.obstacle = {g for g in range(model.ngeom)
                         if (model.id2name(g, "geom") or "").startswith(OBSTACLE_PREFIX)}
        if not self.obstacle:
            raise ValueError(f"no obstacle geoms named {OBSTACLE_PREFIX}* in this scene")
        arm_bodies = set(arm_ids(model, "body").tolist())
        self.arm = {g for g in range(model.ngeom) if int(model.geom_bodyid[g]) in arm_bodies}
        head_body = arm_indices(model).head_body
        self.head = {g for g in self.arm if int(model.geom_bodyid[g]) == head_body}
        self._force = np.zeros(6)
        self._scratch = mujoco.MjData(model.ptr)

    def _touching(self, contacts) -> list:
        """(contact index, arm geom) of every arm-obstacle contact in `contacts`."""
        touching = []
        for i in range(len(contacts.geom1)):
            g1, g2 = int(contacts.geom1[i]), int(contacts.geom2[i])
            other = g2 if g1 in self.obstacle else g1 if g2 in self.obstacle else None
            if other is not None and other in self.arm:
                touching.append((i, other))
        return touching

    def forces(self, physics) -> tuple:
        """(largest arm-obstacle force, largest head-obstacle force) in N; 0 without contact.

        After a dm_control step the contacts are those of the new state but the solver's
        forces (efc_force) still those of the step before (mj_step1 ran last), so the
        forces are solved again on a scratch copy of the state (the simulation is untouched)."""
        if not self._touching(physics.data.contact):
            return 0.0, 0.0
        model, data = physics.model.ptr, self._scratch
        mujoco.mj_copyData(data, model, physics.data.ptr)
        mujoco.mj_forward(model, data)
        arm_force = head_force = 0.0
        for i, other in self._touching(data.contact):
            mujoco.mj_contactForce(model, data, i, self._force)
            force = float(np.linalg.norm(self._force[:3]))
            arm_force = max(arm_force, force)
            if other in self.head:
                head_force = max(head_force, force)
        return arm_force, head_force


def recorder_for(env):
    """`record(env, action, measured)` for `narrow_gap`, with the contact probe of `env`'s model;
    the head from the task's measurement `measured`."""
    probe = ContactProbe(env.physics)

    def record(env, action, measured) -> dict:
        physics, task = env.physics, env.task
        head = measured.head_in_world
        head_xz = measured.head_position
        arm_force, head_force = probe.forces(physics)
        return {
            "time": task.episode_time(physics), "target_index": int(task.target_index),
            "head_x": float(head[0]), "head_z": float(head[2]),
            # distance to every sub-target in the trunk frame, as the task measures it
            "target_errors": [float(np.linalg.norm(physics.to_trunk_frame([x, 0.0, z])[[0, 2]] - head_xz))
                              for x, z in task.world_targets],
            "attitude": measured.head_attitude, "attitude_error": abs(measured.attitude_error),
            "arm_contact_force": arm_force, "head_contact_force": head_force,
            "walking": bool(task.walking()),
        }
    return record


def active_during_step(series: dict) -> np.ndarray:
    """The sub-target each control step was acting towards: the index before the step (a switch
    happens at the end of a step, so the step that reached a sub-target still belongs to it)."""
    index = np.asarray(series["target_index"])
    return np.concatenate([[0], index[:-1]]).astype(int)


def position_error(series: dict) -> np.ndarray:
    """Per step, the distance to the sub-target it acted towards (m)."""
    active = active_during_step(series)
    return np.asarray(series["target_errors"])[np.arange(active.size), active]


def per_target(series: dict, targets, position_tolerance: float) -> list:
    """One row per sub-target: when it was active, reached or not, time to reach, the largest
    arm-obstacle contact force while it was active, head contact."""
    rows = []
    index, time = active_during_step(series), series["time"]
    step = float(time[1] - time[0]) if len(time) > 1 else float(time[0])
    for k, target in enumerate(targets):
        active = np.flatnonzero(index == k)
        row = {"target": k + 1, "position": [float(v) for v in target], "active_from_s": None,
               "reached": False, "time_to_reach_s": None, "min_position_error": None,
               "max_arm_contact_force": 0.0, "head_touched": False}
        if active.size:
            start = float(time[active[0]] - step)
            error = np.asarray(series["target_errors"])[active, k]
            within = np.flatnonzero(error <= position_tolerance)
            row.update(active_from_s=start, active_for_s=float(time[active[-1]] - start),
                       reached=bool(within.size), min_position_error=float(error.min()),
                       time_to_reach_s=float(time[active[within[0]]] - start) if within.size else None,
                       max_arm_contact_force=float(series["arm_contact_force"][active].max()),
                       head_touched=bool(np.any(series["head_contact_force"][active] > 0)))
        rows.append(row)
    return rows


def metrics(series: dict, targets, position_tolerance: float) -> dict:
    """Per-sub-target rows and the seed's success (module doc)."""
    rows = per_target(series, targets, position_tolerance)
    head_touched = bool(np.any(series["head_contact_force"] > 0))
    switches = np.flatnonzero(np.diff(series["target_index"]) != 0) + 1
    return {
        "targets": rows, "reached": int(sum(r["reached"] for r in rows)),
        "final_reached": rows[-1]["reached"], "head_touched": head_touched,
        "success": bool(rows[-1]["reached"] and not head_touched and not series["fell"]),
        "max_arm_contact_force": float(series["arm_contact_force"].max()),
        "final_position_error": float(position_error(series)[-1]),
        "switch_times_s": [float(series["time"][i]) for i in switches],
        "stopped_at_s": (float(series["time"][np.argmin(series["walking"])])
                         if not series["walking"].all() else None),
        "fell": bool(series["fell"]),
    }


def summarize(per_seed: list) -> dict:
    """Over the seeds: success rate, per sub-target reach rate, median time to reach, worst force."""
    n = len(per_seed)
    targets = []
    for k in range(len(per_seed[0]["targets"])):
        rows = [m["targets"][k] for m in per_seed]
        times = [r["time_to_reach_s"] for r in rows if r["time_to_reach_s"] is not None]
        targets.append({"target": k + 1, "reached_rate": sum(r["reached"] for r in rows) / n,
                        "time_to_reach_median_s": float(np.median(times)) if times else None,
                        "max_arm_contact_force": max(r["max_arm_contact_force"] for r in rows)})
    return {"seeds": n, "success_rate": sum(m["success"] for m in per_seed) / n,
            "final_reached_rate": sum(m["final_reached"] for m in per_seed) / n,
            "head_touched_rate": sum(m["head_touched"] for m in per_seed) / n,
            "max_arm_contact_force": max(m["max_arm_contact_force"] for m in per_seed),
            "targets": targets}


def evaluate(policies: list, seeds: int, gait, record_dir: Optional[str] = None, bar=None,
             **task_kwargs) -> dict:
    """Every policy on `seeds` gait phases: per-seed rows, summary; the seed-0 series (for the
    figure) and a Rerun recording of it per policy in `record_dir` (None: none)."""
    report = {}
    for policy in policies:
        per_seed, first = [], None
        recording = None if record_dir is None else os.path.join(record_dir, f"gap_{policy.label}.rrd")
        for seed, env, series in applications.rollouts(policy, TASK, seeds, gait, recorder_for, recording,
                                                       bar, **task_kwargs):
            per_seed.append({"seed": seed, **metrics(series, env.task.world_targets, env.task.position_tolerance)})
            first = series if first is None else first
        report[policy.label] = {"summary": summarize(per_seed), "seeds": per_seed, "series": first}
    return report


def scene() -> dict:
    """The obstacle's outline in the x-z plane (for the figure): wall, shelf pieces, slot."""
    x0, bottom = scenes.GAP_WALL_X, scenes.GAP_SHELF_BOTTOM
    shelf_top = bottom + scenes.GAP_SHELF_THICKNESS
    slot_near = x0 + scenes.GAP_SLOT_X - scenes.GAP_SLOT_WIDTH / 2
    slot_far = x0 + scenes.GAP_SLOT_X + scenes.GAP_SLOT_WIDTH / 2
    return {
        "wall": [x0 - scenes.WALL_THICKNESS, shelf_top, x0, scenes.GAP_WALL_TOP],  # x0, z0, x1, z1
        "shelf_near": [x0 - scenes.WALL_THICKNESS, bottom, slot_near, shelf_top],
        "shelf_far": [slot_far, bottom, x0 + scenes.GAP_SHELF_DEPTH, shelf_top],
        "slot": [slot_near, bottom, slot_far, shelf_top],
    }
