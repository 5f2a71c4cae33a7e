"""Rerun recordings: evaluation rollouts (arm, head path, targets, tendon inputs, errors) and training curves.

A rollout's head, target and errors are the task's measurement of each step
(robostrich_suite/tasks/measurement.py), the reading the evaluation's numbers come from.

The arm itself is drawn by `robostrich_suite.rerun_log` (its geoms as 3D
shapes, body poses per step); other dm_control domains fall back to their
body positions as a line strip (development only).
"""
import contextlib
from typing import Dict, List, Optional

import numpy as np
import rerun as rr
from robostrich_suite import rerun_blueprint, rerun_log


def _point(vector) -> list:
    """A world point as Rerun takes it (plain floats)."""
    return [float(v) for v in vector]


class RolloutRecorder:
    """Streams one rollout to an .rrd file on a `sim_time` timeline, for a `with` block that opens it
    (rerun_log.RecordingFile): the block's end writes `path`, an error or Ctrl-C leaves no
    half-written recording."""

    def __init__(self, path: str, name: str = "rollout", application_id: str = "robostrich"):
        self.path = path
        self.file = rerun_log.RecordingFile(application_id, path, recording_id=name)
        self.rec = None  # the stream, once the `with` block opens it
        self.head_path: List[list] = []
        self.targets: List[list] = []
        self.step = 0
        self._geometry_logged = False

    def _log_arm(self, env):
        """Arm shapes via robostrich_suite.rerun_log (geometry and the layout once, body poses per step)."""
        if not self._geometry_logged:
            self._geometry_logged = True
            self.file.send_blueprint(rerun_blueprint.rollout(side_view=not hasattr(env.physics, "from_trunk_frame")))
            rerun_log.log_geometry(self.rec, env.physics)
            self.rec.log("plots/tendon_input", rr.SeriesLines(  # each line by its tendon's name, not [0]..[8]
                names=[name.split("/")[-1] for name in env.physics.tendon_names()]), static=True)
        rerun_log.log_body_poses(self.rec, env.physics)

    def log_step(self, env, action, timestep, measured):
        """One step: the robot's body poses from the physics; the head, the target and the errors
        from ``measured``, the task's measurement of that step (robostrich_suite/tasks/measurement.py)."""
        physics, rec = env.physics, self.rec
        rec.set_time("sim_time", duration=float(physics.data.time))
        rec.set_time("step", sequence=self.step)
        self.step += 1
        self._log_arm(env)
        if measured.head_in_world is not None:
            head = _point(measured.head_in_world)
            self.head_path.append(head)
            rec.log("world/head", rr.Points3D([head], radii=0.008, colors=[[255, 200, 0]]))
            rec.log("plots/head_attitude_deg", rr.Scalars(measured.head_attitude))
        if measured.target_in_world is not None:
            self._log_target(env, _point(measured.target_in_world))
        if action is not None:
            rec.log("plots/tendon_input", rr.Scalars(np.asarray(action, np.float64)))
        if np.isfinite(measured.position_error):
            rec.log("plots/position_error_m", rr.Scalars(measured.position_error))
        if np.isfinite(measured.attitude_error):
            rec.log("plots/attitude_error_deg", rr.Scalars(abs(measured.attitude_error)))
        if timestep.reward is not None:
            rec.log("plots/reward", rr.Scalars(float(timestep.reward)))

    def _log_target(self, env, target: list) -> None:
        """This step's target, and the list of targets the recording shows at its end."""
        if hasattr(env.physics, "from_trunk_frame"):  # robostrich_a1: the target walks with the trunk
            if not self.targets and hasattr(env.task, "world_targets"):  # narrow_gap's are fixed
                self.targets = [_point([x, 0.0, z]) for x, z in env.task.world_targets]
        elif not self.targets or self.targets[-1] != target:
            self.targets.append(target)
        self.rec.log("world/target", rr.Points3D([target], radii=0.012, colors=[[230, 40, 40]]))

    def close(self):
        if len(self.head_path) > 1:
            self.rec.log("world/head_path", rr.LineStrips3D([self.head_path], radii=0.002,
                                                          colors=[[255, 200, 0]]), static=True)
        if self.targets:
            self.rec.log("world/all_targets", rr.Points3D(self.targets, radii=0.01, colors=[[230, 40, 40]],
                                                          labels=[f"target {i + 1}" for i in range(len(self.targets))]),
                         static=True)
        self.rec = None  # the file's is then the stream's last reference, dropped with Ctrl-C held off
        self.file.close()

    def discard(self):
        self.rec = None
        self.file.discard()

    def __enter__(self):
        self.rec = self.file.open()
        return self

    def __exit__(self, error_type, error, traceback):
        """The recording is written if the block ran to its end, discarded otherwise."""
        self.close() if error_type is None else self.discard()


def open_recorder(path: Optional[str], name: str):
    """A RolloutRecorder writing `path` for a `with` block, or (path None) a block with no recorder."""
    if path is None:
        return contextlib.nullcontext()
    return RolloutRecorder(path, name=name)


CURVE_FIELDS = ("return", "success", "position_error", "attitude_error", "critic_loss", "actor_loss",
                "alpha_loss", "temperature", "entropy")
EVAL_FIELDS = ("success_rate", "position_error_median", "attitude_error_median", "return_mean")


def log_training_curves(path: str, runs: Dict[str, List[dict]], evals: Dict[str, List[dict]] = None):
    """Training curves of each run on an `env_steps` timeline (one .rrd, one entity per run and field)."""
    groups = [(field.replace("_", " "), f"training/{field}") for field in CURVE_FIELDS]
    groups += [(f"held-out {field.replace('_', ' ')}", f"heldout/{field}") for field in EVAL_FIELDS]
    with rerun_log.recording("robostrich", path, recording_id="training",
                             blueprint=rerun_blueprint.curves(groups)) as rec:
        _log_curves(rec, runs, evals or {})


def _log_curves(rec, runs: Dict[str, List[dict]], evals: Dict[str, List[dict]]):
    for label, records in runs.items():
        if not records:
            continue
        steps = np.array([r["env_steps"] for r in records], np.int64)
        for field in CURVE_FIELDS:
            values = np.array([float(r.get(field, np.nan)) for r in records], np.float64)
            keep = np.isfinite(values)
            if keep.any():
                rec.send_columns(f"training/{field}/{label}", indexes=[rr.TimeColumn("env_steps", sequence=steps[keep])],
                                 columns=rr.Scalars.columns(scalars=values[keep]))
    for label, records in evals.items():
        if not records:
            continue
        steps = np.array([r["env_steps"] for r in records], np.int64)
        for field in EVAL_FIELDS:
            if field not in records[0]["summary"]:  # no errors on e.g. reacher; returns only
                continue
            values = np.array([r["summary"][field] for r in records], np.float64)
            rec.send_columns(f"heldout/{field}/{label}", indexes=[rr.TimeColumn("env_steps", sequence=steps)],
                             columns=rr.Scalars.columns(scalars=values))
