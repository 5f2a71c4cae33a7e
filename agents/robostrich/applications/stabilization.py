"""Head stabilisation on the walking quadruped (Sec. 5.2.1, Fig. 9): rollouts and metrics.

`robostrich_a1/head_stabilize` walks 12 s; the trunk height dips at 4-6 s and recovers at
8-10 s.  The head should stay a constant height above the ground, level, and `P_d` ahead of
the trunk (its target, in the trunk frame, is (P_d, height)).  Per control step the rollout
records head and trunk height and vertical velocity (world, height above the ground), the
head-trunk distance along the walk (the head's forward coordinate in the trunk frame), the
head attitude and the desired values.

Metrics are taken after `settle` seconds (default 1 s: every episode starts with the arm
straight up at rest; the first second is the fall into the commanded pose, which no
controller can skip).  The goal numbers are the issue's reading of the paper's Fig. 9.
"""
from typing import Optional

import numpy as np

from agents.robostrich.applications import rollouts as applications

TASK = "head_stabilize"
SETTLE = 1.0  # s excluded from the metrics at the episode start (module doc)
PEAK_HYSTERESIS = 0.002  # m: a crest or trough must stand this far from its neighbours
# metric -> (goal, "max" or "min"): the goal is met when the metric is <= (max) / >= (min) it.
GOALS = {
    "head_vz_rms_ratio": (0.3, "max"),  # head z-velocity RMS / the trunk's
    "height_rms_error": (0.01, "max"),  # m
    "distance_mean_error": (0.02, "max"),  # m, |mean of crests and troughs - P_d|
    "attitude_within_fraction": (0.9, "min"),  # of the time within the attitude tolerance (5 deg)
}


def record(env, action, measured) -> dict:
    """One control step of `head_stabilize` (module doc); the head and its target from the task's
    measurement `measured`."""
    physics, task = env.physics, env.task
    return {
        "time": task.episode_time(physics),
        "head_z": float(measured.head_in_world[2]), "trunk_z": physics.trunk_height(),
        "head_vz": float(physics.head_velocity()[2]), "trunk_vz": float(physics.trunk_velocity()[2]),
        "distance": float(measured.head_position[0]),
        "desired_distance": float(measured.target[0]), "desired_height": float(measured.target[1]),
        "attitude": measured.head_attitude, "desired_attitude": task.desired_attitude,
        "attitude_tolerance": measured.attitude_tolerance, "trunk_height_command": task.trunk_height_command(physics),
    }


def crests_and_troughs(x, hysteresis: float = PEAK_HYSTERESIS):
    """(crests, troughs) of `x`: the turning points of a zig-zag that only turns once the signal
    has come back more than `hysteresis` from its last extreme (jitter below it is ignored)."""
    x = np.asarray(x, np.float64)
    crests, troughs = [], []
    if x.size == 0:
        return np.array(crests), np.array(troughs)
    high = low = x[0]
    direction = 0  # +1 rising (tracking a crest), -1 falling (tracking a trough)
    for value in x[1:]:
        if direction >= 0 and value > high:
            high = value
        if direction <= 0 and value < low:
            low = value
        if direction >= 0 and value < high - hysteresis:
            if direction > 0:
                crests.append(high)
            direction, low = -1, value
        elif direction <= 0 and value > low + hysteresis:
            if direction < 0:
                troughs.append(low)
            direction, high = 1, value
    return np.array(crests), np.array(troughs)


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if len(x) else float("nan")


def metrics(series: dict, settle: float = SETTLE) -> dict:
    """The Fig. 9 numbers of one rollout, from `settle` seconds on (module doc)."""
    keep = series["time"] >= settle
    s = {key: np.asarray(value)[keep] for key, value in series.items() if isinstance(value, np.ndarray)}
    if not keep.any():
        raise ValueError(f"nothing to score: the rollout is {series['time'][-1]:.2f} s long, "
                         f"the first {settle} s are not scored")
    height_error = s["head_z"] - s["desired_height"]
    distance_error = s["distance"] - s["desired_distance"]
    crests, troughs = crests_and_troughs(s["distance"])
    if crests.size and troughs.size:  # the paper's reading of Fig. 9C: the middle of the oscillation
        middle = 0.5 * (crests.mean() + troughs.mean())
    else:
        middle = float(np.mean(s["distance"]))
    attitude_error = np.abs(s["attitude"] - s["desired_attitude"])
    trunk_vz_rms = _rms(s["trunk_vz"])
    return {
        "height_rms_error": _rms(height_error), "height_max_error": float(np.max(np.abs(height_error))),
        "head_vz_rms": _rms(s["head_vz"]), "trunk_vz_rms": trunk_vz_rms,
        "head_vz_rms_ratio": _rms(s["head_vz"]) / trunk_vz_rms if trunk_vz_rms > 0 else float("inf"),
        "distance_mean_error": float(abs(middle - np.mean(s["desired_distance"]))),
        "distance_rms_error": _rms(distance_error),
        "distance_crests": int(crests.size), "distance_troughs": int(troughs.size),
        "attitude_within_fraction": float(np.mean(attitude_error <= s["attitude_tolerance"])),
        "attitude_rms_error": _rms(attitude_error),
        "scored_from_s": float(settle), "scored_steps": int(keep.sum()),
        "fell": bool(series.get("fell", False)),
    }


def goal_check(per_seed: list) -> dict:
    """Per goal: the worst seed's value and whether every seed meets it."""
    checks = {}
    for name, (goal, kind) in GOALS.items():
        values = [m[name] for m in per_seed]
        worst = max(values) if kind == "max" else min(values)
        met = all((v <= goal) if kind == "max" else (v >= goal) for v in values)
        checks[name] = {"goal": goal, "kind": kind, "worst": float(worst), "met": bool(met and
                                                                                     not any(m["fell"] for m in per_seed))}
    return checks


def summarize(per_seed: list) -> dict:
    """Mean, min and max over the seeds of every numeric metric."""
    out = {}
    for key in per_seed[0]:
        values = np.array([m[key] for m in per_seed], np.float64)
        if key in ("scored_from_s",):
            continue
        out[key] = {"mean": float(values.mean()), "min": float(values.min()), "max": float(values.max())}
    return out


def evaluate(policies: list, seeds: int, gait, settle: float = SETTLE, record_dir: Optional[str] = None,
             bar=None, record_name: str = "stabilize_{label}.rrd", **task_kwargs) -> dict:
    """Every policy on `seeds` gait phases: per-seed metrics, summary, goals; the seed-0 series
    (for the figure) and a Rerun recording of it per policy in `record_dir` (None: none), named
    `record_name` with the policy's label."""
    import os
    report = {}
    for policy in policies:
        per_seed, first = [], None
        recording = None if record_dir is None else os.path.join(record_dir, record_name.format(label=policy.label))
        for seed, env, series in applications.rollouts(policy, TASK, seeds, gait, lambda env: record, recording,
                                                       bar, **task_kwargs):
            per_seed.append({"seed": seed, **metrics(series, settle)})
            first = series if first is None else first
        scores = [{k: v for k, v in m.items() if k != "seed"} for m in per_seed]
        report[policy.label] = {"summary": summarize(scores), "goals": goal_check(scores), "seeds": per_seed,
                                "series": first}
    return report
