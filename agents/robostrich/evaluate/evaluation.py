"""Evaluation of the deterministic policy: held-out targets and the three-target `track` task (Fig. 7).

On the arm every held-out target is tried from the fixed start (`heldout`) and
from three poses where the arm holds another target (`heldout_moving`); so are new targets, level
poses at least 1 cm from every pose the agent trained on (`new`, `new_moving`: each new target from
one of the three starts in turn; robostrich_suite/studies/new_targets.py), and the no-learning
`lookup` baseline (agents/robostrich/lookup.py) is evaluated beside the agents. Other dm_control
domains report episode returns. Writes one JSON report per evaluation; a checkpoint's run is rebuilt here too (`load_run_from_checkpoint`). The
command `robostrich-evaluate` is agents/robostrich/evaluate/command.py.
"""
import os
import shutil
import tempfile
from typing import Optional

import numpy as np

from agents import checkpoint
from agents.curriculum import LessonSettings
from agents.replay import ObservationFlattener
from agents.robostrich.domains import as_domain, domain_of, TRACK_TASK
from agents.robostrich.lookup import LABEL, LookupPolicy
from agents.robostrich.evaluate import lookup_cache
from agents.robostrich.recording import open_recorder
from agents.robostrich.domain_run import DomainRun, current_fingerprint, make_environment, parse_plan
from agents.sac.config import SACConfig
from robostrich_suite import atomic_files, parsing
from robostrich_suite import cli as cli_lib
from robostrich_suite.tasks.conventions import PRECISE_ATTITUDE_TOLERANCE_DEG, PRECISE_POSITION_TOLERANCE
from robostrich_suite.tasks.measurement import measure

MAX_TARGETS = 10_000  # held-out targets (or seeded episodes off the arm) of one evaluation
target_count = cli_lib.whole_number(1, MAX_TARGETS)  # argparse type of the target counts
REPORT_KINDS = ("heldout", "heldout_moving", "new", "new_moving", "track")  # of evaluate_agent, in its order
KIND_NAMES = {"heldout": "held-out, fixed start", "heldout_moving": "held-out, moving starts",  # as printed
              "new": "new targets, fixed start", "new_moving": "new targets, moving starts", "track": "track"}


def rollout(env, actor, flattener, on_step=None, action_repeat: int = 1) -> dict:
    """One episode with `actor` (acting every `action_repeat` control steps); per-control-step series
    of the task's measurement (robostrich_suite/tasks/measurement.py), read once per step.
    ``on_step(env, action, timestep, measured)``, if given, sees every step as it happens (a
    recording's ``log_step``; action None at the reset)."""
    timestep = env.reset()
    physics = env.physics
    measured = measure(env)
    has_head = measured.head_position is not None
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
        measured = measure(env)
        series["time"].append(float(physics.data.time))
        series["position_error"].append(measured.position_error)
        series["attitude_error"].append(abs(measured.attitude_error))
        series["reward"].append(float(timestep.reward))
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


def default_heldout_task(domain, final_task: str) -> str:
    """lesson2 on the arm: reward eq. 10 from the fixed initial pose, so every target starts alike."""
    return as_domain(domain).heldout_task(final_task)


def check_heldout_task(domain, task: str) -> str:
    """``task`` if it is a task of ``domain`` that takes one held-out target (on the arm, a
    lesson; not ``track``, which sets its own), else a ValueError naming --heldout-task."""
    domain = as_domain(domain)
    try:
        domain.check_task(task)
        if domain.is_arm:
            make_environment(domain, task, 0, target_pool=domain.heldout_targets(1)).close()
    except (TypeError, ValueError) as error:
        raise ValueError(f"--heldout-task {task!r} cannot be evaluated on held-out targets: {error}") from None
    return task


def check_track_task(domain, requested: Optional[str]) -> Optional[str]:
    """The track task to evaluate: ``requested`` where ``domain`` has it; None for '' or the
    default ``track`` on a domain without it (the quadruped); any other name must be a task
    of ``domain`` (ValueError naming --track-task), not skipped without a word."""
    domain = as_domain(domain)
    if requested and requested != TRACK_TASK:
        try:
            domain.check_task(requested)
        except ValueError as error:
            raise ValueError(f"--track-task: {error}") from None
    return domain.track_task(requested)


def evaluate_heldout(actor, flattener, domain, task: str, num_targets: Optional[int] = None,
                     seed: int = 10_000, targets=None, action_repeat: int = 1, on_episode=None,
                     kind: str = "heldout") -> dict:
    """Deterministic policy, one episode per held-out target (a pool of that single target).

    Use a task with a fixed initial state (lesson2): every target then starts from the same pose.
    The domain's held-out targets (None off the arm: seeded episodes) unless ``targets`` are given.
    """
    domain = as_domain(domain)
    report = {"kind": kind, **domain.info(), "task": task}
    if targets is None:
        targets = domain.heldout_targets(num_targets)
    episodes = []
    count = len(targets) if targets is not None else (num_targets or 10)
    env = None
    for i in range(count):
        if targets is None:
            env = domain.make_environment(task, seed + i)
        elif env is not None:
            env.task.set_target_pool(targets[i])  # reuse the compiled model (building one takes ~0.3 s)
        else:
            env = domain.make_environment(task, seed, target_pool=targets[i:i + 1])
        row = _episode_summary(rollout(env, actor, flattener, action_repeat=action_repeat))
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
            row = _episode_summary(rollout(env, actor, flattener, action_repeat=action_repeat))
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


def evaluate_agent(actor, flattener, out_dir: str, label: str, domain, heldout_task: str,
                   track_task: Optional[str], num_targets: Optional[int] = None, env_steps: int = None,
                   record: bool = True, action_repeat: int = 1, on_episode=None, new_targets=None) -> dict:
    """Held-out (+ from moving starts on the arm), new-target (``new_targets``, (n, 2) in the
    domain's frame, or None) and track evaluation, JSON reports and (optionally) a Rerun
    recording of the track rollout. ``on_episode()`` is called after each of its `episode_count` episodes."""
    os.makedirs(out_dir, exist_ok=True)
    moving = as_domain(domain).has_moving_starts
    reports = {"heldout": evaluate_heldout(actor, flattener, domain, heldout_task, num_targets,
                                           action_repeat=action_repeat, on_episode=on_episode)}
    if moving:
        reports["heldout_moving"] = evaluate_heldout_moving(actor, flattener, domain, num_targets,
                                                            action_repeat=action_repeat, on_episode=on_episode)
    if new_targets is not None and len(new_targets):
        reports["new"] = evaluate_heldout(actor, flattener, domain, heldout_task, targets=new_targets,
                                          action_repeat=action_repeat, on_episode=on_episode, kind="new")
        if moving:
            reports["new_moving"] = evaluate_heldout_moving(actor, flattener, domain, targets=new_targets,
                                                            action_repeat=action_repeat, on_episode=on_episode,
                                                            kind="new_moving", one_start_each=True)
    if track_task:
        with open_recorder(os.path.join(out_dir, f"{label}_track.rrd") if record else None,
                           f"{label} track") as recorder:
            reports["track"] = evaluate_track(actor, flattener, domain, track_task, recorder=recorder,
                                              action_repeat=action_repeat)
        if on_episode:
            on_episode()
    for kind, report in reports.items():
        report.update(label=label, env_steps=env_steps)
        atomic_files.write_json(os.path.join(out_dir, f"{label}_{kind}.json"), report)
    return reports


def episode_count(domain, num_targets: Optional[int], track_task: Optional[str], new_targets: int = 0) -> int:
    """Episodes of one `evaluate_agent` (for its progress bar): each held-out target from the fixed
    start and, on the arm, from each moving start; each of ``new_targets`` new targets from the
    fixed start and from one moving start; one `track` episode."""
    domain = as_domain(domain)
    targets = domain.heldout_targets(num_targets)
    count = len(targets) if targets is not None else (num_targets or 10)
    moving = domain.has_moving_starts
    return (count * (1 + (len(domain.moving_starts()[0]) if moving else 0)) + new_targets * (1 + moving)
            + bool(track_task))


def outcome_text(kind: str, s: dict) -> str:
    """One evaluation's outcome in words: success at the task's tolerances, the share within 1 cm and
    2 deg, the median final errors and how many targets (episodes, from moving starts)."""
    return (f"{s['success_rate'] * 100:5.1f} % reached ({s['precise_success_rate'] * 100:.1f} % within 1 cm and "
            f"2 deg), median error {s['position_error_median'] * 100:.2f} cm, {s['attitude_error_median']:.2f} deg, "
            f"{s['episodes']} {'episodes' if kind == 'heldout_moving' else 'targets'}")


def summary_lines(runs: dict) -> list:
    """What a person reads at the end of an evaluation (the JSON stays in the files): per run and
    kind, ``outcome_text`` (as robostrich-play prints it), or the return off the arm.
    ``runs``: label -> kind -> summary."""
    lines = []
    for label, kinds in runs.items():
        for kind, s in kinds.items():
            head = f"{label:10s} {KIND_NAMES.get(kind, kind) + ':':27s}"
            label = ""
            if "success_rate" not in s:
                lines.append(f"{head} return {s['return_mean']:.1f} mean [{s['return_min']:.1f}, "
                             f"{s['return_max']:.1f}], {s['episodes']} episodes")
                continue
            lines.append(f"{head} {outcome_text(kind, s)}")
    return lines


def read_reports(out_dir: str, label: str) -> dict:
    """The reports `evaluate_agent` wrote for `label` (kind -> report), e.g. by a worker process."""
    reports = {}
    for kind in REPORT_KINDS:
        path = os.path.join(out_dir, f"{label}_{kind}.json")
        if os.path.exists(path):
            reports[kind] = parsing.read_json(path)  # a torn file is one ValueError naming it
    return reports


def evaluate_lookup(out_dir: str, domain, heldout_task: str, track_task: Optional[str],
                    num_targets: Optional[int] = None, record: bool = True, on_episode=None,
                    new_targets=None) -> Optional[dict]:
    """`evaluate_agent` for the lookup baseline (label `lookup`) on the arm; None on other domains.
    The same evaluation made before (the same routing, targets, tasks and code) is copied from its
    cache instead (agents/robostrich/evaluate/lookup_cache.py).

    Action repeat 1: the lookup's input only changes with the target.
    """
    domain = as_domain(domain)
    if not domain.is_arm:
        return None
    digest = lookup_cache.key(domain, heldout_task, track_task, num_targets, new_targets, record)
    restored = lookup_cache.restore(digest, out_dir)
    if restored is not None:
        if on_episode:
            for _ in range(episode_count(domain, num_targets, track_task,
                                         0 if new_targets is None else len(new_targets))):
                on_episode()
        return {name[len(LABEL) + 1:-len(".json")]: parsing.read_json(os.path.join(out_dir, name))
                for name in restored if name.endswith(".json")}
    flattener = ObservationFlattener(make_environment(domain, heldout_task, 0).observation_spec())
    reports = evaluate_agent(LookupPolicy(flattener, domain.lookup_table()), flattener, out_dir, LABEL, domain,
                             heldout_task, track_task, num_targets, env_steps=0, record=record, action_repeat=1,
                             on_episode=on_episode, new_targets=new_targets)
    lookup_cache.keep(digest, out_dir, [f"{LABEL}_{kind}.json" for kind in reports]
                      + ([f"{LABEL}_track.rrd"] if record and "track" in reports else []))
    return reports


def checked_fingerprint(path: str) -> dict:
    """The fingerprint of a robostrich-train checkpoint, after checking that it holds
    what a run is rebuilt from: a CheckpointError naming what it lacks, before anything is built."""
    record, _ = checkpoint.read_with_digest(path)
    fp = current_fingerprint(record["fingerprint"])
    missing = ([k for k in ("plan", "config", "lessons", "seed") if k not in fp]
               + [k for k in DomainRun.STATE_FIELDS if k not in record["payload"]])
    if missing:
        raise checkpoint.CheckpointError(f"{path} is not a whole robostrich-train checkpoint: it lacks {missing}")
    try:
        parse_plan(fp["plan"])
    except (TypeError, ValueError) as error:
        raise checkpoint.CheckpointError(f"{path} holds a damaged plan: {error}") from None
    return fp


def checkpoint_domain(fingerprint: dict):
    """The domain (and layout) a checkpoint's run trained its last lesson on."""
    return domain_of({"domain": parse_plan(fingerprint["plan"])[-1].domain, "layout": fingerprint.get("layout")},
                     fingerprint.get("task_kwargs"))


def load_run_from_checkpoint(path: str):
    """Rebuild the DomainRun that wrote `path` (its fingerprint holds config, plan and seed)."""
    fp = checked_fingerprint(path)
    scratch = tempfile.mkdtemp(prefix="robostrich-evaluate-")  # the run's own files are left untouched
    try:
        run = DomainRun(parse_plan(fp["plan"]), SACConfig.from_dict(fp["config"]), fp["seed"], scratch,
                        task_kwargs=fp.get("task_kwargs"), layout=fp.get("layout"), init_from=fp.get("init_from"),
                        lessons=LessonSettings.from_dict(fp["lessons"]), residual_scale=fp.get("residual_scale", 0.0))
        run.restore(path)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return run
