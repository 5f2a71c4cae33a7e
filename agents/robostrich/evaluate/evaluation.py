"""Evaluation reports of the deterministic policy: held-out targets and the three-target `track` task (Fig. 7).

On the arm every held-out target is tried from the fixed start (`heldout`) and
from three poses where the arm holds another target (`heldout_moving`); so are new targets, level
poses at least 1 cm from every pose the agent trained on (`new`, `new_moving`: each new target from
one of the three starts in turn; robostrich_suite/studies/new_targets.py), and the no-learning
`lookup` baseline (agents/robostrich/lookup.py) is evaluated beside the agents. Other dm_control
domains report episode returns. Writes one JSON report per evaluation; a checkpoint's run is rebuilt here too (`load_run_from_checkpoint`). The
episodes themselves are agents/robostrich/evaluate/episodes.py; the command `robostrich-evaluate` is
agents/robostrich/evaluate/command.py.
"""
import os
import shutil
import tempfile
from typing import Optional

from agents import checkpoint
from agents.replay import ObservationFlattener
from agents.robostrich.domains import as_domain, domain_of, TRACK_TASK
from agents.robostrich.lookup import LABEL, LookupPolicy
from agents.robostrich.evaluate import episodes, lookup_cache
from agents.robostrich.recording import open_recorder
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import RunSpec, migrate, parse_plan
from robostrich_suite import atomic_files, parsing
from robostrich_suite import cli as cli_lib

MAX_TARGETS = 10_000  # held-out targets (or seeded episodes off the arm) of one evaluation
target_count = cli_lib.whole_number(1, MAX_TARGETS)  # argparse type of the target counts
REPORT_KINDS = ("heldout", "heldout_moving", "new", "new_moving", "track")  # of evaluate_agent, in its order
KIND_NAMES = {"heldout": "held-out, fixed start", "heldout_moving": "held-out, moving starts",  # as printed
              "new": "new targets, fixed start", "new_moving": "new targets, moving starts", "track": "track"}


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
            domain.make_environment(task, 0, target_pool=domain.heldout_targets(1)).close()
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


def evaluate_agent(actor, flattener, out_dir: str, label: str, domain, heldout_task: str,
                   track_task: Optional[str], num_targets: Optional[int] = None, env_steps: int = None,
                   record: bool = True, action_repeat: int = 1, on_episode=None, new_targets=None) -> dict:
    """Held-out (+ from moving starts on the arm), new-target (``new_targets``, (n, 2) in the
    domain's frame, or None) and track evaluation, JSON reports and (optionally) a Rerun
    recording of the track rollout. ``on_episode()`` is called after each of its `episode_count` episodes."""
    os.makedirs(out_dir, exist_ok=True)
    domain = as_domain(domain)
    moving = domain.has_moving_starts
    reports = {"heldout": episodes.evaluate_heldout(actor, flattener, domain, heldout_task,
                                                    domain.heldout_targets(num_targets), num_targets,
                                                    action_repeat=action_repeat, on_episode=on_episode)}
    if moving:
        reports["heldout_moving"] = episodes.evaluate_heldout_moving(actor, flattener, domain, num_targets,
                                                            action_repeat=action_repeat, on_episode=on_episode)
    if new_targets is not None and len(new_targets):
        reports["new"] = episodes.evaluate_heldout(actor, flattener, domain, heldout_task, new_targets,
                                                   action_repeat=action_repeat, on_episode=on_episode, kind="new")
        if moving:
            reports["new_moving"] = episodes.evaluate_heldout_moving(actor, flattener, domain, targets=new_targets,
                                                            action_repeat=action_repeat, on_episode=on_episode,
                                                            kind="new_moving", one_start_each=True)
    if track_task:
        with open_recorder(os.path.join(out_dir, f"{label}_track.rrd") if record else None,
                           f"{label} track") as recorder:
            reports["track"] = episodes.evaluate_track(actor, flattener, domain, track_task, recorder=recorder,
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
    flattener = ObservationFlattener(domain.make_environment(heldout_task, 0).observation_spec())
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
    fp = migrate(record["fingerprint"])
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
        run = DomainRun(RunSpec.from_fingerprint(fp), scratch)
        run.restore(path)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return run
