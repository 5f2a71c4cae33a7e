"""Evaluation episodes of a deterministic policy: every held-out (or given) target from the fixed
start, from poses where the arm holds another target (moving starts), and the `track` task (Fig. 7);
each an episode record, and their summary. The reports and the lookup beside them:
agents/robostrich/evaluate/evaluation.py."""
from typing import Optional

import numpy as np

from agents.robostrich.domains import Domain, as_domain
from robostrich_suite import cli as cli_lib
from robostrich_suite.tasks import measurement
from robostrich_suite.tasks.conventions import PRECISE_ATTITUDE_TOLERANCE_DEG, PRECISE_POSITION_TOLERANCE
from robostrich_suite.tasks.measurement import measure


def rollout(env, actor, flattener, on_step=None, action_repeat: int = 1, errors_only: bool = False) -> dict:
    """One episode with `actor` (acting every `action_repeat` control steps); per-control-step series
    of the task's measurement (robostrich_suite/tasks/measurement.py), read once per step.
    ``on_step(env, action, timestep, measured)``, if given, sees every step as it happens (a
    recording's ``log_step``; action None at the reset). ``errors_only``: only the series an
    episode's summary reads (the errors and the rewards), for evaluations that keep no series."""
    if errors_only and on_step is not None:
        raise ValueError("a rollout that keeps only the errors has no measurement to show on_step")
    timestep = env.reset()
    physics = env.physics
    measured = measure(env)
    has_head = measured.head_position is not None and not errors_only
    series = {k: [] for k in ("time", "position_error", "attitude_error", "head_position", "head_attitude",
                              "target", "action", "reward")}
    # the task's own tolerances, not the paper's constants
    series["tolerances"] = [measured.position_tolerance, measured.attitude_tolerance]
    if on_step is not None:
        on_step(env, None, timestep, measured)
    step = 0
    while not timestep.last():
        cli_lib.raise_if_interrupted()  # a Ctrl-C some library swallowed
        if step % action_repeat == 0:
            action = actor.select_action(flattener(timestep.observation))
        timestep = env.step(action)
        step += 1
        series["reward"].append(float(timestep.reward))
        if errors_only:
            position_error, attitude_error = measurement.errors(env)
            series["position_error"].append(position_error)
            series["attitude_error"].append(abs(attitude_error))
            continue
        measured = measure(env)
        series["time"].append(float(physics.data.time))
        series["position_error"].append(measured.position_error)
        series["attitude_error"].append(abs(measured.attitude_error))
        series["action"].append(np.asarray(action, np.float64).tolist())
        if has_head:
            series["head_position"].append(measured.head_position.tolist())
            series["head_attitude"].append(measured.head_attitude)
            series["target"].append(measured.target.tolist())
        if on_step is not None:
            on_step(env, action, timestep, measured)
    return series


def _episode_summary(series, start=0, end=None) -> dict:
    pe = np.asarray(series["position_error"][start:end])
    ae = np.asarray(series["attitude_error"][start:end])
    episode_return = float(np.sum(series["reward"][start:end]))
    if np.all(np.isnan(pe)):  # a domain without a head or target (e.g. reacher): its return is all there is
        return {"return": episode_return, "steps": int(pe.size)}
    position_tolerance, attitude_tolerance = series["tolerances"]
    within = (pe <= position_tolerance) & (ae <= attitude_tolerance)
    reached = np.flatnonzero(within)
    return {
        "final_position_error": float(pe[-1]), "final_attitude_error": float(ae[-1]),
        "min_position_error": float(pe.min()),
        "success": bool(within[-1]),  # the task's success rule on the last step
        "tolerances": [float(position_tolerance), float(attitude_tolerance)],
        "steps_to_reach": int(reached[0] + 1) if reached.size else None,
        "steps": int(pe.size), "return": episode_return,
    }


def summarize(episodes) -> dict:
    """Success (the task's tolerances, and the precise reach of ``conventions``) and final errors
    (robostrich, point_mass); only return statistics where errors are unknown."""
    returns = np.array([e["return"] for e in episodes], np.float64)
    return_stats = {"return_mean": float(returns.mean()), "return_std": float(returns.std()),
                    "return_min": float(returns.min()), "return_max": float(returns.max())}
    if any("final_position_error" not in e for e in episodes):
        return {"episodes": len(episodes), **return_stats}
    pe = np.array([e["final_position_error"] for e in episodes])
    ae = np.array([e["final_attitude_error"] for e in episodes])
    reach = [e["steps_to_reach"] for e in episodes if e["steps_to_reach"] is not None]
    return {
        "episodes": len(episodes),
        "success_rate": float(np.mean([e["success"] for e in episodes])),
        "precise_success_rate": float(np.mean((pe <= PRECISE_POSITION_TOLERANCE)
                                              & (np.abs(ae) <= PRECISE_ATTITUDE_TOLERANCE_DEG))),
        "precise_tolerances": [PRECISE_POSITION_TOLERANCE, PRECISE_ATTITUDE_TOLERANCE_DEG],
        "position_error_median": float(np.median(pe)), "position_error_p90": float(np.percentile(pe, 90)),
        "attitude_error_median": float(np.median(ae)), "attitude_error_p90": float(np.percentile(ae, 90)),
        "reached_fraction": len(reach) / len(episodes),
        "steps_to_reach_median": float(np.median(reach)) if reach else None,
        "position_tolerance_m": episodes[0]["tolerances"][0],
        "attitude_tolerance_deg": episodes[0]["tolerances"][1],
        **return_stats,
    }


def evaluate_heldout(actor, flattener, domain: Domain, task: str, targets, count: Optional[int] = None,
                     seed: int = 10_000, action_repeat: int = 1, on_episode=None, kind: str = "heldout") -> dict:
    """Deterministic policy, one episode per target of ``targets`` (a pool of that single target; the
    domain's held-out ones: ``Domain.heldout_targets``); None off the arm: ``count`` (default 10)
    episodes seeded from ``seed``, judged by their returns.

    Use a task with a fixed initial state (lesson2): every target then starts from the same pose.
    """
    report = {"kind": kind, **domain.info(), "task": task}
    episodes = []
    count = len(targets) if targets is not None else (count or 10)
    env = None
    for i in range(count):
        if targets is None:
            env = domain.make_environment(task, seed + i)
        elif env is not None:
            env.task.set_target_pool(targets[i])  # reuse the compiled model (building one takes ~0.3 s)
        else:
            env = domain.make_environment(task, seed, target_pool=targets[i:i + 1])
        row = _episode_summary(rollout(env, actor, flattener, action_repeat=action_repeat, errors_only=True))
        if targets is not None:
            row["target"] = targets[i].tolist()
        episodes.append(row)
        if on_episode:
            on_episode()
    return {**report, "summary": summarize(episodes), "episodes": episodes}


def evaluate_heldout_moving(actor, flattener, domain="robostrich", num_targets: Optional[int] = None,
                            seed: int = 30_000, targets=None, starts=None, action_repeat: int = 1,
                            on_episode=None, kind: str = "heldout_moving", one_start_each: bool = False) -> dict:
    """Every held-out target from poses where the arm holds another target (lesson 3's situation).

    One lesson-3 environment: per start, an episode from the fixed pose holds
    the start's stored inputs (2 s: the arm comes to rest there); then, per
    held-out target, the task's `continue` initial state starts the evaluated
    episode from that resting state. `starts` = (positions, controls). With
    ``one_start_each`` target i is tried from start i mod the number of starts only.
    """
    domain = as_domain(domain)
    task = domain.moving_start_task
    report = {"kind": kind, **domain.info(), "task": task}
    targets = domain.heldout_targets(num_targets) if targets is None else np.asarray(targets, np.float64)
    start_positions, start_controls = domain.moving_starts() if starts is None else starts
    env = domain.make_environment(task, seed, target_pool=targets[:1])
    episodes = []
    for k, (start, control) in enumerate(zip(start_positions, start_controls)):
        rest, held = _rest_at(env, start, control)
        for target in (targets[k::len(start_positions)] if one_start_each else targets):
            env.task.set_initial_state("continue")
            if rest is None:  # the hold diverged: from the fixed pose, as a diverged episode's successor
                env.task.forget_last_state()
            env.task.continue_next_from(rest)
            env.task.set_target_pool(target)
            row = _episode_summary(rollout(env, actor, flattener, action_repeat=action_repeat, errors_only=True))
            row.update(target=np.asarray(target).tolist(), start=k, start_target=np.asarray(start).tolist(),
                       start_position_error=held.position_error, start_attitude_error=abs(held.attitude_error))
            episodes.append(row)
            if on_episode:
                on_episode()
    return {**report, "summary": summarize(episodes), "episodes": episodes}


def _rest_at(env, start, control):
    """(the state a `continue` episode starts from, the measurement there) after holding ``control``
    for an episode from the fixed pose, the target at ``start``: deterministic, so one hold serves
    every target from that start."""
    env.task.set_initial_state("fixed")
    env.task.set_target_pool(start)
    timestep = env.reset()
    while not timestep.last():
        timestep = env.step(control)
    return env.physics.continuing_state(), measure(env)


def evaluate_track(actor, flattener, domain="robostrich", task: str = "track", seed: int = 20_000,
                   recorder=None, action_repeat: int = 1) -> dict:
    """The `track` task: targets in order (Fig. 7); one summary per target segment plus the series."""
    domain = as_domain(domain)
    report = {"kind": "track", **domain.info(), "task": task}
    env = domain.make_environment(task, seed)
    series = rollout(env, actor, flattener, recorder.log_step if recorder is not None else None,
                     action_repeat=action_repeat)
    segments = []
    targets = series["target"]
    bounds = [0] + [i for i in range(1, len(targets)) if targets[i] != targets[i - 1]] + [len(series["time"])]
    for start, end in zip(bounds[:-1], bounds[1:]):
        row = _episode_summary(series, start, end)
        row.update(start_step=start, target=targets[start] if targets else None)
        segments.append(row)
    return {**report, "segments": segments, "summary": summarize(segments), "series": series}
