"""The main job: curriculum SAC (lessons 1->3) and a plain-SAC baseline, then evaluation, figures and recordings.

    robostrich-train                               # defaults: writes runs/default (its time: docs/results.md)
    robostrich-train --out runs/default --resume   # continue a killed run from its last checkpoints

Run directory:
    config.json                  the command line and resolved configuration
    curriculum/, baseline/       checkpoint.ckpt, metrics.jsonl (one line per episode), evals.jsonl
    evaluation/                  <label>_heldout.json, <label>_heldout_moving.json, <label>_track.json,
                                 <label>_track.rrd; labels curriculum, baseline and (on the arm) lookup
    figures/                     learning_curves.png, track.png
    training.rrd                 training curves of both runs
    summary.json
"""
import argparse
import dataclasses
import json
import os
import sys
import time
import typing
from collections import deque
from typing import Optional

import numpy as np

from agents.robostrich import directory_lock, evaluation
from agents.curriculum import Lesson, LessonSettings, format_plan, read_records, run_files
from agents.robostrich.runs import DEFAULT_LESSONS, DomainRun, check_lesson_names, parse_plan, run_identity
from agents.robostrich.domains import Domain
from agents.robostrich.lookup import LABEL as LOOKUP_LABEL
from agents.sac.builder import SACBuilder
from agents.sac.config import SACConfig
from robostrich_suite import cli as cli_lib
from robostrich_suite import parsing
from robostrich_suite.model import layouts

DEFAULT_TOTAL_STEPS = 480_000  # per run, split evenly over the lessons; the two runs train side by side
# The main job on the frame arm: lessons 1-2 keep 160k control steps each and lesson 3, where the
# policy refines its reach from moving starts, gets the longest share (280k of 600k), training with
# a narrower policy Gaussian (target entropy -3 per action instead of -2: about 1 % of an input's
# range instead of 3 %, where a held input 1 % off already costs a target): the long, quiet lesson is
# what makes the reach precise
# (docs/log/learning.md#a-longer-quieter-lesson-3-714--within-1-cm-and-2-deg-on-every-seed-2026-12-02).
# On the quadruped (Algorithm 1 as the paper ran it) lessons 1-3 on the standing quadruped get the
# frame's 600k, then lesson 4 (trotting, the trunk height changing) 150k more.
MAIN_JOB_STEPS = {"robostrich": 600_000, "robostrich_a1": 750_000}
MAIN_JOB_LESSON_SHARES = {"robostrich": (4, 4, 7), "robostrich_a1": (16, 16, 28, 15)}  # of the curriculum, in order
# Lesson 4 starts with an empty replay: continuing on the standing lessons' transitions, its own
# success fell while it trained, and with it the standing targets
# (docs/log/quadruped.md#2026-12-03-hindsight-goals-were-off-lesson-4-after-them-the-head-speed-term).
_NARROW_LESSON3 = {"exploration_lessons": ("lesson3",), "exploration_target_entropy_per_action": -3.0}
MAIN_JOB_CONFIG = {"robostrich": _NARROW_LESSON3,  # LessonSettings fields
                   "robostrich_a1": {**_NARROW_LESSON3, "fresh_replay_lessons": ("lesson4",)}}
MAX_TOTAL_STEPS = 100_000_000  # per run: about three days on 2 CPU cores
# On the arm domains the main job trains the tasks' own routing, the reconstruction of the paper's
# Fig. 1B (robostrich_suite.model.layouts.DEFAULT); `--layout antagonist_pairs` trains the best
# routing of our own.
DEFAULT_ARM_LAYOUT = layouts.DEFAULT
# Task arguments of every training lesson on the arm domains, under the ones --task-kwargs gives:
# a Gaussian position term that keeps paying inside the 5 cm tolerance (rewards.RewardWeights), so
# the learner still gains by coming closer once it is inside; targets drawn by how often the agent
# misses them (Reach target_sampling "failures"); and a quarter of lessons 1-2's episodes started
# at rest at a stored pose (Reach fixed_stored_starts), so that lesson 3 takes over a learner that
# has already moved out of its curled starts, which every low-to-high move needs; and the same
# Gaussian term for the head's attitude (1 deg scale), which holds the head level well inside the
# 5 deg tolerance (docs/log/learning.md#the-attitude-precision-term-becomes-the-default-24-of-24-track-targets-2026-12-01
# and the sections below it). '{"weights": {"position_precision": 0, "attitude_precision": 0},
# "target_sampling": "uniform", "fixed_stored_starts": 0}' gives the paper's eq. 10, draw and
# starts. Evaluation keeps the task's defaults.
DEFAULT_ARM_TASK_KWARGS = {"weights": {"position_precision": 1.0, "attitude_precision": 0.5},
                           "target_sampling": "failures", "fixed_stored_starts": 0.25}
# The same with lessons 1-2 starting fixed, for arms whose stored poses (a layout's lookup table)
# are not shipped: the candidate arms of robostrich-layouts --train.
FIXED_START_ARM_TASK_KWARGS = {**DEFAULT_ARM_TASK_KWARGS, "fixed_stored_starts": 0.0}


# On the quadruped a quarter of lesson 4's episodes stand (the standing lessons rehearsed): trained
# on trotting alone, the policy could lose standing targets it had held after lesson 3
# (docs/log/quadruped.md#2026-12-04-lesson-4-rehearses-standing-what-limits-the-heads-vertical-speed).
# The standing lessons ignore the option.
QUADRUPED_TASK_KWARGS = {"standing_share": 0.25}


def default_task_kwargs(domain: Domain) -> dict:
    """The main job's task arguments on `domain` (none off the arm): the same on the frame and on
    the quadruped, where the arm holds the stored poses as on the frame, plus lesson 4's rehearsal."""
    if not domain.is_arm:
        return {}
    return {**DEFAULT_ARM_TASK_KWARGS, **(QUADRUPED_TASK_KWARGS if domain.on_quadruped else {})}


def resolve_layout(layout: Optional[str], domain: Domain) -> Optional[str]:
    """The tendon layout a run trains: the one asked for, else the main job's on an arm domain."""
    return layout if layout is not None or not domain.is_arm else DEFAULT_ARM_LAYOUT


def resolve_task_kwargs(task_kwargs: dict, domain: Domain) -> dict:
    """--task-kwargs over the main job's defaults on an arm domain (``weights`` merged key by key,
    so '{"weights": {"position_error": 10}}' keeps the precision term; set it to 0 to drop it)."""
    defaults = default_task_kwargs(domain)
    merged = {**defaults, **task_kwargs}
    if "weights" in defaults and isinstance(task_kwargs.get("weights"), dict):
        merged["weights"] = {**defaults["weights"], **task_kwargs["weights"]}
    return merged


def check_task_kwargs(plan, layout, task_kwargs: dict) -> None:
    """Build each lesson's environment once with ``task_kwargs``, so that an unknown option or a
    bad value is a one-line error naming --task-kwargs now, not a worker's traceback later."""
    for domain_name, task in dict.fromkeys((lesson.domain, lesson.task) for lesson in plan):
        try:
            env = Domain(domain_name, layout).make_environment(task, 0, **task_kwargs)
        except (TypeError, ValueError) as error:
            raise ValueError(f"--task-kwargs {json.dumps(task_kwargs, default=str)} does not suit "
                             f"{domain_name}/{task}: {error}") from error
        env.close()


def check_residual_scale(scale: float, config: SACConfig) -> float:
    """--residual-scale in [0, 2] and not with hindsight goals (a new goal changes the lookup's action)."""
    if not 0.0 <= scale <= 2.0:
        raise ValueError(f"--residual-scale must be in [0, 2] (0 = no residual), got {scale}")
    if scale > 0 and config.her_ratio > 0:
        raise ValueError("--residual-scale and --her-ratio do not mix: a relabelled goal changes the lookup's "
                         "action, so the stored residual would no longer mean what it did (add --her-ratio 0)")
    return float(scale)


def check_goal_free_terms(task_kwargs: dict, config: SACConfig) -> None:
    """The reward's action-change and head-speed terms do not depend on the goal: rewards the replay
    recomputes for goals (hindsight, ``relabel_rewards``) would silently drop them, so they need both off."""
    weights = task_kwargs.get("weights")
    for term in ("action_change", "head_vertical_speed"):
        weight = weights.get(term, 0) if isinstance(weights, dict) else getattr(weights, term, 0)
        if weight and (config.relabel_rewards or config.her_ratio > 0):
            raise ValueError(f"--task-kwargs weights.{term} needs the replay to keep the rewards the task "
                             "gave (recomputing them for goals drops the term): add --no-relabel-rewards --her-ratio 0")


def lesson_text(run) -> str:
    """'2/3': the lesson a run is in, for the progress bar."""
    return f"{run.lesson_index + 1 if not run.done else len(run.plan)}/{len(run.plan)}"


class Progress:
    """tqdm bar over all control steps of all runs: steps/s, run, lesson, recent return and
    success; then a second bar over the final evaluations' episodes (``evaluations`` of them)."""

    def __init__(self, total: int, enabled: bool = True, evaluations: int = 0):
        self.bar = self.eval_bar = None
        self.enabled, self.evaluations = enabled, evaluations
        if enabled:
            from tqdm import tqdm
            self.bar = tqdm(total=total, unit="step", dynamic_ncols=True, smoothing=0.05)
        self.returns = deque(maxlen=20)
        self.successes = deque(maxlen=50)

    def skip(self, n: int):
        """n steps a resumed run had already taken: counted as done, not into the steps/s."""
        if self.bar is not None and n:
            self.bar.n += n
            self.bar.last_print_n += n
            self.bar.initial += n
            self.bar.refresh()

    def evaluated(self, n: int = 1):
        """n more episodes of the final evaluations (the bar appears with the first)."""
        if not self.enabled or not self.evaluations:
            return
        if self.eval_bar is None:
            from tqdm import tqdm
            self.eval_bar = tqdm(total=self.evaluations, desc="final evaluation", unit="episode",
                                 dynamic_ncols=True, position=1)
        self.eval_bar.update(n)

    def on_episode(self, record):
        self.returns.append(record["return"])
        self.successes.append(float(record["success"]))

    def update(self, n, run):
        self.advance(n, run.name, lesson_text(run))

    def advance(self, n, label: str, lesson: str):
        """n more steps of run `label`, now in `lesson` (also what worker processes report)."""
        if self.bar is None:
            return
        self.bar.update(n)
        self.bar.set_postfix(run=label, lesson=lesson,
                             ret=f"{np.mean(self.returns) if self.returns else float('nan'):.1f}",
                             succ=f"{np.mean(self.successes) if self.successes else float('nan'):.2f}",
                             refresh=False)

    def reset_window(self):
        self.returns.clear()
        self.successes.clear()

    def close(self, cleared: bool = False):
        """Close the bars (``cleared``: wipe them, the command stopped early)."""
        for bar in (self.eval_bar, self.bar):
            if bar is not None:
                bar.leave = bar.leave and not cleared
                bar.close()


positive_int = cli_lib.whole_number(1, MAX_TOTAL_STEPS)  # control steps


def _json_object(text: str) -> dict:
    try:
        value = parsing.loads_json(text)
    except ValueError as error:  # torn, or nested too deeply
        raise argparse.ArgumentTypeError(str(error)) from None
    if not isinstance(value, dict):
        raise argparse.ArgumentTypeError(f"expected a JSON object, got {type(value).__name__}")
    return value


def _scales(text: str) -> dict:
    from robostrich_suite.tasks import perturbations
    try:
        return perturbations.parse_scales(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def apply_randomize(scales: Optional[dict], task_kwargs: dict, domain: Domain) -> dict:
    """--randomize FAMILY=S,... as the task options: the robot drawn per episode up to each scale
    (robostrich_suite/tasks/perturbations.py, ``vary``) and, with latency, the last
    ``MAX_LATENCY_STEPS`` sent actions observed, so that what is on its way to the servos is in
    the observation (unless --task-kwargs sets ``observe_sent_actions``)."""
    if not scales:
        return task_kwargs
    from robostrich_suite.tasks import perturbations
    if not domain.is_arm:
        raise ValueError(f"--randomize applies to the arm domains, not to {domain.name!r}")
    if "perturbation" in task_kwargs:
        raise ValueError("--randomize and --task-kwargs' perturbation both set the robot's differences; give one")
    families = perturbations.FAMILIES if domain.on_quadruped else perturbations.ARM_FAMILIES
    try:
        perturbation = perturbations.training_perturbation(scales, families)
    except ValueError as error:
        raise ValueError(f"--randomize: {error}") from None
    extra = {"perturbation": perturbation}
    if perturbation.get("latency"):
        extra["observe_sent_actions"] = task_kwargs.get("observe_sent_actions", perturbations.MAX_LATENCY_STEPS)
    return {**task_kwargs, **extra}


def _add_run_arguments(run) -> None:
    """robostrich-train's flags for what to train: domain, plan, seed, layout, start, workers."""
    run.add_argument("--domain", default="robostrich",
                     help="robostrich (the arm on its frame), robostrich_a1 (on the quadruped) or a dm_control "
                          "domain (default: %(default)s)")
    run.add_argument("--steps", type=positive_int, default=None,
                     help="total control steps of the curriculum (default "
                          + "; ".join(f"{MAIN_JOB_STEPS[d]} on {d}, split "
                                      f"{':'.join(map(str, MAIN_JOB_LESSON_SHARES[d]))} "
                                      "over its lessons" for d in MAIN_JOB_STEPS)
                          + f"; {DEFAULT_TOTAL_STEPS} elsewhere, split evenly)")
    run.add_argument("--lessons", default=None,
                     help="lesson tasks, in order (default: the domain's curriculum: lesson1-3 on robostrich, "
                          "lesson1-4 on robostrich_a1)")
    run.add_argument("--plan", default=None,
                     help="explicit plan '[domain/]task:steps,...' (overrides --steps/--lessons)")
    run.add_argument("--seed", type=cli_lib.seed, default=0,
                     help="random seed of networks, exploration and episodes (default: %(default)s)")
    run.add_argument("--layout", default=None,
                     help="built-in tendon layout of the arm; its own shipped level poses give the training and "
                          f"held-out targets and the lookup table (default on the arm domains: {DEFAULT_ARM_LAYOUT}, "
                          "the reconstruction of the paper's routing; antagonist_pairs: the best routing of our own)")
    run.add_argument("--init-from", default=None, metavar="CHECKPOINT",
                     help="start the curriculum's learner (policy, critics, target critics, optimiser states, "
                          "temperature) from a checkpoint.ckpt of robostrich-train on the same domain or, for "
                          "--domain robostrich_a1, on robostrich (the arm on its frame): its networks are mapped "
                          "onto the a1's observations (agents/robostrich/transfer.py). Same tendon layout and networks "
                          "(--hidden-sizes) required; the replay is not carried (other observations); the plain-SAC "
                          "baseline still starts from scratch, so the comparison shows what the transfer brings. "
                          "A --resume may leave it out (the checkpoint holds the transferred state)")
    run.add_argument("--task-kwargs", type=_json_object, default={},
                     help="JSON object passed to every training lesson's task, e.g. eq. 10's weights: "
                          "'{\"weights\": {\"position_error\": 10}}' (evaluation keeps the task's defaults). On the "
                          f"arm domains it goes over {json.dumps(DEFAULT_ARM_TASK_KWARGS)}, on robostrich_a1 also "
                          f"{json.dumps(QUADRUPED_TASK_KWARGS)} (weights merged key by key; "
                          "'{\"weights\": {\"position_precision\": 0, \"attitude_precision\": 0}, "
                          "\"target_sampling\": \"uniform\", "
                          "\"fixed_stored_starts\": 0}' gives the paper's eq. 10, its uniform draw of targets and "
                          "its fixed starts in lessons 1-2)")
    run.add_argument("--randomize", type=_scales, default=None, metavar="FAMILY=S,...",
                     help="train across robots that differ from the model: each episode draws each family's "
                          "scale from [0, S] (families and scales as robostrich-robustness measures them, "
                          "robostrich_suite/tasks/perturbations.py; all=S for every family); with latency the "
                          "policy also observes its last 3 sent actions, which evaluation and its policy file "
                          "carry (default: the nominal robot)")
    run.add_argument("--baseline", action=argparse.BooleanOptionalAction, default=True,
                     help="also train plain SAC on the final lesson with the same total budget (default: "
                          "--baseline)")
    run.add_argument("--workers", type=cli_lib.whole_number(1, cli_lib.MAX_WORKERS),
                     default=min(2, os.cpu_count() or 1),
                     help="runs trained at once, one process each (default: %(default)s; the curriculum and "
                          "the plain-SAC baseline are independent)")


def _add_file_arguments(files) -> None:
    """robostrich-train's flags for the run directory and its checkpoints."""
    files.add_argument("--out", default="runs/default", help="run directory (default: %(default)s)")
    files.add_argument("--resume", action="store_true", help="continue from the checkpoints in --out")
    files.add_argument("--keep-lesson-checkpoints", action="store_true",
                       help="also keep a checkpoint after every lesson but the last (RUN/after_lessonK.ckpt), "
                            "e.g. the lesson-3 policy to compare lesson 4 with (robostrich-stabilize --reference)")
    files.add_argument("--checkpoint-every", type=positive_int, default=25_000,
                       help="control steps between checkpoints (default: %(default)s)")


def _add_report_arguments(report) -> None:
    """robostrich-train's flags for the evaluations and what is written."""
    report.add_argument("--eval-every", type=positive_int, default=None,
                        help="control steps between held-out evaluations (default: steps/6)")
    report.add_argument("--num-eval-targets", type=evaluation.target_count, default=20,
                        help="held-out targets in the periodic evaluations (the final one uses all; "
                             "default: %(default)s)")
    report.add_argument("--final-eval-targets", type=evaluation.target_count, default=None,
                        help="held-out targets in the final evaluation (default: all)")
    report.add_argument("--heldout-task", default=None,
                        help="task for held-out evaluation (default: lesson2 on robostrich, i.e. eq. 10 from the "
                             "fixed initial pose; else the final lesson)")
    report.add_argument("--track-task", default="track",
                        help="task of the final tracking evaluation; '' to skip it (default: %(default)s)")
    report.add_argument("--no-rerun", action="store_true", help="no .rrd recordings of the final evaluation")
    report.add_argument("--no-figures", action="store_true", help="no PNG figures")
    report.add_argument("--quiet", action="store_true", help="no progress bar")


def build_parser():
    p = cli_lib.Parser(description="Train curriculum SAC (and a plain-SAC baseline) on the Robostrich arm.")
    _add_run_arguments(p.add_argument_group("what to train"))
    _add_file_arguments(p.add_argument_group("run directory and checkpoints"))
    _add_report_arguments(p.add_argument_group("evaluation and outputs"))
    p.add_argument("--stop-at-step", type=positive_int, default=None, help=argparse.SUPPRESS)  # imitates a kill (tests)
    add_agent_arguments(p)
    return p


def add_agent_arguments(p) -> None:
    """The agent's settings (SACConfig), what changes per lesson (LessonSettings), the residual and --paper-sac."""
    add_config_arguments(p.add_argument_group("SAC (defaults: agents/sac/config.py)"), SACConfig())
    lessons = p.add_argument_group("per lesson (agents/curriculum.py LessonSettings; defaults: "
                                   "agents/robostrich/runs.py DEFAULT_LESSONS)")
    add_config_arguments(lessons, DEFAULT_LESSONS)
    lessons.add_argument("--residual-scale", type=float, default=0.0,
                         help="train a residual on the lookup's stored inputs, within this fraction of each "
                              "tendon's half-range (0, the default: the policy gives the whole input)")
    p.add_argument("--paper-sac", action="store_true",
                   help="the paper's plain SAC (Acme defaults, no agent improvements, nothing per lesson); "
                        "flags given explicitly still apply on top")


def _config_flag(field_name: str) -> str:
    """The flag of one config field: ``--field-name``."""
    return "--" + field_name.replace("_", "-")


def _shown(value, field_name: str = "") -> str:
    """A default as --help shows it: a tuple as its flag takes it, an empty lesson list by its keyword."""
    if isinstance(value, tuple) and not value and field_name in LessonSettings.LESSON_LIST_FIELDS:
        return _EMPTY_LESSONS[field_name == "her_lessons"]
    return ",".join(map(str, value)) if isinstance(value, tuple) else str(value)


# An empty lesson list means every lesson for hindsight goals and no lesson for the rest
# (LessonSettings): on the command line each is said in a word, `all` or `none`.
_EMPTY_LESSONS = {True: "all", False: "none"}


def add_config_arguments(group, defaults):
    """One flag per field of ``defaults``' dataclass (``--field-name``), its default read from it:
    the dataclass is the one home of the training defaults, the CLI only exposes them."""
    for field in dataclasses.fields(defaults):
        default = getattr(defaults, field.name)
        flag = _config_flag(field.name)
        help_text = f"{type(defaults).HELP[field.name]} (default: {_shown(default, field.name)}"
        for domain, values in MAIN_JOB_CONFIG.items():
            if field.name in values:
                help_text += f"; on {domain}: {_shown(values[field.name], field.name)}"
        help_text += ")"
        if isinstance(default, bool):
            group.add_argument(flag, dest=field.name, action=argparse.BooleanOptionalAction,
                               default=default, help=help_text)
        elif isinstance(default, tuple):
            item_type = typing.get_args(typing.get_type_hints(type(defaults))[field.name])[0]
            group.add_argument(flag, dest=field.name, type=_comma_list(item_type, field.name),
                               default=_shown(default, field.name), help=help_text)
        elif default is None:
            group.add_argument(flag, dest=field.name, type=float, default=None, help=help_text)
        else:
            group.add_argument(flag, dest=field.name, type=type(default), default=default, help=help_text)


def _comma_list(item_type, field_name: str = ""):
    """argparse type of a tuple field: the text as given once every item reads as ``item_type``,
    else a usage error naming the flag (int's own words would not). A lesson list's keyword
    (`all` for hindsight goals, `none` for the rest) reads as the empty list it stands for."""

    def parse(text: str) -> str:
        if field_name in LessonSettings.LESSON_LIST_FIELDS:
            keyword = _EMPTY_LESSONS[field_name == "her_lessons"]
            if text.strip() == keyword:
                return ""
            if not text.strip() and field_name == "her_lessons":  # elsewhere empty means none, as it says
                raise argparse.ArgumentTypeError(f"name the lessons, separated by commas, or {keyword}")
        for item in filter(None, (part.strip() for part in text.split(","))):
            try:
                item_type(item)
            except ValueError:
                kind = "whole numbers" if item_type is int else f"{item_type.__name__} values"
                raise argparse.ArgumentTypeError(f"expected {kind} separated by commas, got {text!r} "
                                                 f"({item!r} is not one)") from None
        return text
    return parse


def config_from_args(args, argv=None, cls=SACConfig):
    """The ``cls`` (SACConfig or LessonSettings) the flags give: under --paper-sac the paper's
    (nothing per lesson), else the main job's settings on its domain, explicit flags on top."""
    values = {f.name: getattr(args, f.name) for f in dataclasses.fields(cls)}
    hints = typing.get_type_hints(cls)
    for field in dataclasses.fields(cls):  # tuple fields come as "64,64" or "lesson1,lesson2"
        if isinstance(field.default, tuple):
            item_type = typing.get_args(hints[field.name])[0]
            values[field.name] = tuple(item_type(item.strip()) for item in str(values[field.name]).split(",")
                                       if item.strip())
    explicit = _explicit_fields(argv, cls)
    if getattr(args, "paper_sac", False):
        paper = SACConfig.paper_sac() if cls is SACConfig else LessonSettings()
        values = {k: (v if k in explicit else getattr(paper, k)) for k, v in values.items()}
    else:  # the main job's settings on its domain, under the flags given
        values.update({k: v for k, v in MAIN_JOB_CONFIG.get(getattr(args, "domain", None), {}).items()
                       if k not in explicit and k in values})
    try:
        return cls(**values)
    except ValueError as error:  # SACConfig names its fields; the user typed flags
        raise ValueError(_with_flags(str(error))) from None


def _with_flags(message: str) -> str:
    """``message`` with every config field name replaced by its flag(s), e.g. learning_rate -> --learning-rate."""
    import re
    flags = {f.name: _config_flag(f.name) for cls in (SACConfig, LessonSettings) for f in dataclasses.fields(cls)}
    return re.sub(r"\b(" + "|".join(sorted(flags, key=len, reverse=True)) + r")\b",
                  lambda m: flags[m.group(1)], message)


def _explicit_fields(argv, cls=SACConfig) -> set:
    """Fields of ``cls`` named on the command line (so --paper-sac does not override them)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    named = set()
    for field in dataclasses.fields(cls):
        flag = _config_flag(field.name)
        for token in argv:
            option = token.split("=", 1)[0]
            if option in (flag, "--no-" + flag[2:]):
                named.add(field.name)
    return named


def plan_from_args(args):
    if args.plan:
        try:
            plan = parse_plan(args.plan, default_domain=args.domain)
        except ValueError as error:
            raise ValueError(f"--plan: {error}") from None
        if sum(l.steps for l in plan) > MAX_TOTAL_STEPS:
            raise ValueError(f"--plan asks for {sum(l.steps for l in plan)} steps, more than {MAX_TOTAL_STEPS}")
        return plan
    if args.lessons is None:
        tasks = list(Domain(args.domain).curriculum())
    else:
        tasks = [t.strip() for t in args.lessons.split(",") if t.strip()]
        if not tasks:
            raise ValueError(f"--lessons {args.lessons!r} names no task, e.g. --lessons lesson1,lesson2")
    total = args.steps if args.steps is not None else MAIN_JOB_STEPS.get(args.domain, DEFAULT_TOTAL_STEPS)
    shares = MAIN_JOB_LESSON_SHARES.get(args.domain) if args.lessons is None else None
    shares = shares or (1,) * len(tasks)
    steps = [total * share // sum(shares) for share in shares[:-1]]
    steps.append(total - sum(steps))
    if min(steps) < 1:
        raise ValueError(f"--steps {total} leaves a lesson without a step ({len(tasks)} lessons)")
    return [Lesson(args.domain, t, s) for t, s in zip(tasks, steps)]


def lock_run_directory(out: str):
    """Make ``out`` this run's (agents/robostrich/directory_lock.py), held while the returned file
    stays open."""
    return directory_lock.lock_directory(out, "robostrich-train")


def _previous_init_path(out: str) -> Optional[str]:
    """The --init-from path config.json recorded when this run started (a --resume may leave it out)."""
    try:
        with open(os.path.join(out, "config.json")) as f:
            return (json.load(f).get("init_from") or {}).get("path")
    except (OSError, ValueError):
        return None


def read_jsonl(path):
    """The records of a run's metrics.jsonl or evals.jsonl (agents.curriculum.read_records)."""
    return read_records(path)


@dataclasses.dataclass(frozen=True)
class RunJob:
    """What a run does besides training: periodic and final evaluation (picklable, for a worker)."""

    domain: Domain
    heldout_task: str
    track_task: Optional[str]
    eval_at: tuple
    num_eval_targets: int
    final_eval_targets: Optional[int]
    out_eval: str
    record: bool
    stop_at_step: Optional[int] = None


@dataclasses.dataclass(frozen=True)
class RunSpec:
    """Everything a DomainRun is built from (picklable): the parent process of a parallel
    job passes it to a worker instead of building the run (networks, replay, environment)
    itself, which it would only throw away."""

    label: str
    plan: tuple
    config: SACConfig
    seed: int
    run_dir: str
    checkpoint_every: int
    task_kwargs: Optional[dict]
    layout: Optional[str]
    lessons: LessonSettings = DEFAULT_LESSONS
    residual_scale: float = 0.0
    init_from: Optional[str] = None  # a checkpoint to start a fresh run's learner from (agents/robostrich/transfer.py)
    init_digest: Optional[str] = None  # its content hash, kept in the run's fingerprint
    keep_lesson_checkpoints: bool = False  # also a checkpoint after every lesson but the last

    @property
    def total_steps(self) -> int:
        return sum(l.steps for l in self.plan)

    def build(self, restore: bool) -> DomainRun:
        """The run; restored from its checkpoint when ``restore`` and one exists (raises on a
        damaged or mismatched checkpoint, never restarts silently)."""
        run = DomainRun(list(self.plan), self.config, self.seed, self.run_dir,
                        checkpoint_every=self.checkpoint_every, name=self.label,
                        task_kwargs=self.task_kwargs, layout=self.layout, init_from=self.init_digest,
                        keep_lesson_checkpoints=self.keep_lesson_checkpoints, lessons=self.lessons,
                        residual_scale=self.residual_scale)
        if restore and os.path.exists(run.checkpoint_path):
            run.restore()
        elif self.init_from is not None:
            from agents.robostrich import transfer
            transfer.initialize(run, self.init_from, self.init_digest)
        return run


@dataclasses.dataclass(frozen=True)
class LookupSpec:
    """The no-learning lookup's final evaluation as a job of its own: in a parallel job it takes the
    core the first finished run frees instead of running alone after both."""

    label: str = LOOKUP_LABEL
    total_steps: int = 0

    def evaluate(self, job: RunJob, progress=None) -> Optional[dict]:
        return evaluation.evaluate_lookup(job.out_eval, job.domain, job.heldout_task, job.track_task,
                                          job.final_eval_targets, record=job.record,
                                          on_episode=progress.evaluated if progress is not None else None)


def final_targets(job: RunJob) -> Optional[int]:
    """Held-out targets of a final (or end-of-lesson) evaluation: all of the arm's unless
    --final-eval-targets says; off the arm as many seeded episodes as the periodic ones."""
    return job.final_eval_targets or (None if job.domain.is_arm else job.num_eval_targets)


def train_and_evaluate(run: DomainRun, job: RunJob, progress=None) -> dict:
    """Finish `run`'s plan (periodic held-out evaluations in its evals.jsonl), then its final
    evaluation (JSON reports in job.out_eval). Returns the reports and the run's counters."""
    config = run.config
    timing = None
    if not run.done:
        if progress is not None:
            progress.reset_window()

        def on_eval(r):
            actor = SACBuilder.make_eval_actor(r.loop)
            lesson_end = r.loop.env_steps in _boundaries(r.plan)[:-1]  # evaluated on every held-out target
            targets = final_targets(job) if lesson_end else job.num_eval_targets
            report = evaluation.evaluate_heldout(actor, r.loop.flattener, job.domain, job.heldout_task,
                                                 targets, action_repeat=config.action_repeat)
            record = {"env_steps": r.loop.env_steps, "lessons_completed": r.lesson_index, "summary": report["summary"]}
            if lesson_end:
                record["lesson_end"] = True
            with open(r.evals_path, "a") as f:
                f.write(json.dumps(record) + "\n")

        start, start_steps = time.time(), run.loop.env_steps
        from robostrich_suite import files
        with files.naming(run.run_dir, only_unnamed=True), cli_lib.deferred_interrupts():
            # Ctrl-C: a checkpoint between chunks, then KeyboardInterrupt; a failed write of the
            # run's records (a full disk) names where the run writes
            run.run(progress=progress, on_eval=on_eval, eval_at=job.eval_at, stop_at_step=job.stop_at_step,
                    stop_requested=cli_lib.interrupted)
        timing = {"seconds": time.time() - start, "env_steps": run.loop.env_steps - start_steps,
                  "updates": run.loop.learner.num_updates}
    reports = evaluation.evaluate_agent(SACBuilder.make_eval_actor(run.loop), run.loop.flattener, job.out_eval,
                                        run.name, job.domain, job.heldout_task, job.track_task, final_targets(job),
                                        env_steps=run.loop.env_steps, record=job.record,
                                        action_repeat=config.action_repeat,
                                        on_episode=progress.evaluated if progress is not None else None)
    return {"reports": reports, "env_steps": run.loop.env_steps, "updates": run.loop.learner.num_updates,
            "timing": timing}


class _QueueProgress:
    """Stands in for `Progress` inside a worker: forwards steps and episodes to the parent's bar."""

    def __init__(self, queue, label):
        self.queue, self.label = queue, label

    def on_episode(self, record):
        self.queue.put(("episode", self.label, {"return": record["return"], "success": record["success"]}))

    def update(self, n, run):
        self.queue.put(("steps", self.label, (n, lesson_text(run))))

    def reset_window(self):
        pass

    def evaluated(self, n: int = 1):
        self.queue.put(("evaluated", self.label, n))


def _worker(spec: RunSpec, job, queue):
    """One run in its own process: restore its latest checkpoint (if any), train, evaluate.
    Ctrl-C (the terminal's, or the parent's on another run's error) writes a checkpoint first."""
    import signal
    label = spec.label
    signal.signal(signal.SIGINT, signal.default_int_handler)  # the parent started it ignored
    try:
        if isinstance(spec, LookupSpec):
            spec.evaluate(job, _QueueProgress(queue, label))
            outcome = {}
        else:
            run = spec.build(restore=True)
            queue.put(("resumed", label, run.loop.env_steps))  # where a resumed run starts
            outcome = train_and_evaluate(run, job, _QueueProgress(queue, label))
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # done: a late request to stop changes nothing
        queue.put(("done", label, {k: v for k, v in outcome.items() if k != "reports"}))
    except KeyboardInterrupt as error:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent asks again until it hears this
        queue.put(("interrupted", label, str(error)))
    except (ValueError, OSError) as error:  # a user error: the parent's one line says it all
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # nor a traceback of the parent's later asks
        from robostrich_suite import cli as cli_lib
        queue.put(("user_error", label, cli_lib.error_message(error)))
    except BaseException as error:  # a bug: its traceback follows, the parent names the run
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        queue.put(("error", label, f"{type(error).__name__}: {error}"))
        raise


def _train_in_parallel(specs: dict, job: RunJob, progress, workers: int) -> dict:
    """Each run in its own process (one core each): the curriculum and the plain-SAC baseline are
    independent, so on two cores the main job takes the time of one run. Workers restore from and
    write the same checkpoints as a sequential run, so results are identical and resumable."""
    import multiprocessing
    context = multiprocessing.get_context("spawn")
    queue = context.Queue()
    # One intra-op thread per worker; set before the spawned interpreters import JAX.
    saved = os.environ.get("XLA_FLAGS")
    os.environ["XLA_FLAGS"] = ((saved or "") + " --xla_cpu_multi_thread_eigen=false"
                               " intra_op_parallelism_threads=1").strip()
    active = {}
    ends = {"done": {}, "error": {}, "user_error": {}, "interrupted": {}}  # how each run ended
    with cli_lib.deferred_interrupts():
        try:
            _supervise(context, specs, job, progress, workers, queue, active, ends)
        finally:
            for process in active.values():
                process.terminate()
            if saved is None:
                os.environ.pop("XLA_FLAGS", None)
            else:
                os.environ["XLA_FLAGS"] = saved
    for kind, error in (("error", RuntimeError), ("user_error", ValueError)):
        if ends[kind]:
            raise error("; ".join(f"{label}: {message}" for label, message in ends[kind].items()))
    if ends["interrupted"]:
        raise KeyboardInterrupt(_stopped_workers(ends["interrupted"]))
    outcomes = ends["done"]
    for label, outcome in outcomes.items():
        outcome["reports"] = evaluation.read_reports(job.out_eval, label)
    return outcomes


def _stopped_workers(stopped: dict) -> str:
    """The interrupt's message from the workers' (label -> message): the checkpoints they wrote
    first, 'checkpoint written at step N: PATH; at step M: PATH', as the command's line shows one."""
    written = cli_lib.CHECKPOINT_WRITTEN
    saved = [message[len(written):].strip() for message in stopped.values() if message.startswith(written)]
    others = [f"{label}: {message}" for label, message in stopped.items() if message and not message.startswith(written)]
    return "; ".join(([f"{written} " + "; ".join(saved)] if saved else []) + others)


def _supervise(context, specs, job, progress, workers, queue, active, ends):
    """Start workers, forward their progress and collect how each ended (``ends``). On Ctrl-C or
    a run's error no run is started, and the running ones are asked (SIGINT, once a second until
    they answer) to write a checkpoint and stop."""
    import queue as queue_lib
    import signal
    pending = list(specs)
    while pending or active:
        stopping = cli_lib.interrupted() or ends["error"] or ends["user_error"]
        if stopping:
            pending.clear()
            for process in active.values():
                if process.is_alive():
                    os.kill(process.pid, signal.SIGINT)
        while pending and len(active) < workers:
            label = pending.pop(0)
            # the worker builds the run from the same seed, or restores it; it starts with Ctrl-C
            # ignored (a KeyboardInterrupt while it imports would print a traceback) and takes it
            # up in _worker
            ignored = signal.signal(signal.SIGINT, signal.SIG_IGN)
            try:
                process = context.Process(target=_worker, args=(specs[label], job, queue))
                process.start()
            finally:
                signal.signal(signal.SIGINT, ignored)
            active[label] = process
        try:
            kind, label, payload = queue.get(timeout=1.0)
        except queue_lib.Empty:  # check for workers that died without a word
            for label, process in list(active.items()):
                if not process.is_alive():
                    ends["interrupted" if stopping else "error"].setdefault(
                        label, f"worker exited with status {process.exitcode}")
                    del active[label]
            continue
        if kind == "steps":
            progress.advance(payload[0], label, payload[1])
        elif kind == "episode":
            progress.on_episode(payload)
        elif kind == "evaluated":
            progress.evaluated(payload)
        elif kind == "resumed":
            progress.skip(payload)
        elif label in active:  # the first word on how it ended
            ends[kind][label] = payload
            active.pop(label).join()


def main(argv=None):
    """The main job: parse and check everything, train every run, evaluate, report; returns the summary."""
    args = build_parser().parse_args(argv)
    from robostrich_suite import outputs
    outputs.check_directory(args.out)  # before a minute of building, not after an hour of training
    setup = prepare(args, argv)
    init = check_run_directory(args, setup)
    with lock_run_directory(args.out):  # released, and its file removed, however this ends
        finished = finished_summary(args, setup)
        if finished is not None:  # a --resume of a finished run: its results, not a second evaluation
            print(f"{args.out} is finished; nothing to resume")
            print_summary(args.out, finished)
            return finished
        specs, runs = start_runs(args, argv, setup, init)
        outcomes, lookup = train_all(args, setup, specs, runs)
        return report(args, setup, specs, outcomes, lookup)


@dataclasses.dataclass
class _Setup:
    """What the command line resolves to before anything is built."""
    config: SACConfig
    lessons: LessonSettings
    residual_scale: float
    plan: list
    domain: Domain
    heldout_task: str
    track_task: Optional[str]
    run_plans: dict


def prepare(args, argv) -> _Setup:
    """Config, plan, domain, layout and task options from ``args``, every name and value checked."""
    config = config_from_args(args, argv)
    lessons = config_from_args(args, argv, LessonSettings)
    residual_scale = check_residual_scale(args.residual_scale, config)
    plan = plan_from_args(args)
    final = plan[-1]
    final_domain = Domain(final.domain)
    args.layout = resolve_layout(args.layout, final_domain)
    args.task_kwargs = apply_randomize(getattr(args, "randomize", None),
                                       resolve_task_kwargs(args.task_kwargs, final_domain), final_domain)
    try:
        domain = Domain(final.domain, args.layout)
    except ValueError as error:
        raise ValueError(str(error) if "--layout" in str(error) else f"--layout {args.layout}: {error}") from None
    for lesson in plan:  # a typo fails now, not after the first lessons have trained
        Domain(lesson.domain).check_task(lesson.task)
    check_task_kwargs(plan, args.layout, args.task_kwargs)
    domain = dataclasses.replace(domain, sent_actions=args.task_kwargs.get("observe_sent_actions", 0))
    check_goal_free_terms(args.task_kwargs, config)
    try:
        check_lesson_names(plan, config, lessons, args.layout)
    except ValueError as error:  # it names the settings' fields; the user typed flags
        raise ValueError(_with_flags(str(error))) from None
    heldout_task = evaluation.check_heldout_task(domain, args.heldout_task or domain.heldout_task(final.task))
    track_task = evaluation.check_track_task(domain, args.track_task)
    run_plans = {"curriculum": plan}
    if args.baseline:
        run_plans["baseline"] = [Lesson(final.domain, final.task, sum(l.steps for l in plan))]
    return _Setup(config, lessons, residual_scale, plan, domain, heldout_task, track_task, run_plans)


def check_run_directory(args, setup: _Setup) -> dict:
    """Refuse a fresh run over checkpoints, a resume of nothing, and a resume of another
    configuration or a damaged file, before anything is built or written; returns the
    curriculum's --init-from (path and content hash), if any."""
    from agents import checkpoint
    existing = [l for l in setup.run_plans if os.path.exists(os.path.join(args.out, l, checkpoint.FILE_NAME))]
    pickled = [os.path.join(l, checkpoint.PICKLED_FILE_NAME) for l in setup.run_plans
               if os.path.exists(os.path.join(args.out, l, checkpoint.PICKLED_FILE_NAME))]
    if pickled and not existing:  # neither resumed nor trained over: its checkpoints are another format's
        raise ValueError(f"{args.out} holds checkpoints written with pickle by an earlier version ({', '.join(pickled)}), "
                         "which this version does not read; train again in another --out")
    if not args.resume and existing:
        raise ValueError(f"{args.out} already holds checkpoints ({', '.join(existing)}); "
                         "pass --resume to continue them or choose another --out")
    if args.resume and not existing:  # a typo in --out must not quietly start the whole job afresh
        looked = ", ".join(os.path.join(l, checkpoint.FILE_NAME) for l in setup.run_plans)
        where = (f"{args.out} holds no checkpoint ({looked})" if os.path.isdir(args.out)
                 else f"{args.out} does not exist")
        raise FileNotFoundError(f"--resume: nothing to resume: {where}; check --out, or leave out --resume "
                                "to start a fresh run")
    init = {}
    if args.init_from is not None:
        from agents.robostrich import transfer
        source = transfer.check_source(args.init_from, setup.plan, setup.config, args.layout,
                                       residual_scale=setup.residual_scale)
        init = {"init_from": source.path, "init_digest": source.digest}
    for label in existing if args.resume else ():
        init = _check_resumed(args, setup, label, init)
    return init


def _check_resumed(args, setup: _Setup, label: str, init: dict) -> dict:
    """One run's checkpoint against this command line (and its records' lines); the --init-from
    a started curriculum recorded."""
    from agents import checkpoint
    path = os.path.join(args.out, label, checkpoint.FILE_NAME)
    stored = checkpoint.read_fingerprint(path)
    if label == "curriculum":  # a started run's learner is in its checkpoint: --init-from may be left out
        if init and stored.get("init_from") != init["init_digest"]:
            raise ValueError(f"{path} did not start from --init-from {args.init_from} "
                             + ("(nor from any checkpoint)" if "init_from" not in stored else
                                "(it started from another checkpoint, or that file has changed since)"))
        init = {**init, "init_digest": stored["init_from"]} if "init_from" in stored else {}
    expected = run_identity(setup.run_plans[label], setup.config, args.seed, setup.lessons, args.task_kwargs,
                            args.layout, init.get("init_digest") if label == "curriculum" else None,
                            setup.residual_scale)
    checkpoint.check_fingerprint({k: stored.get(k, "<missing>") for k in expected}, expected, path)
    for records in run_files(os.path.join(args.out, label))[1:]:
        read_records(records)  # a damaged line other than a torn last one, named
    return init


def start_runs(args, argv, setup: _Setup, init: dict):
    """The runs' specs (and, trained here, the runs themselves, restored on --resume); a run that
    died before its first checkpoint loses its records; config.json. Returns (specs, runs)."""
    specs = {label: RunSpec(label, tuple(run_plan), setup.config, args.seed, os.path.join(args.out, label),
                            args.checkpoint_every, args.task_kwargs, args.layout, setup.lessons,
                            setup.residual_scale, keep_lesson_checkpoints=args.keep_lesson_checkpoints,
                            **(init if label == "curriculum" else {}))  # the baseline starts from scratch
             for label, run_plan in setup.run_plans.items()}
    # Sequential: build (and restore) every run here; parallel: the workers do, once each.
    runs = {} if _parallel(args, specs) else {label: spec.build(restore=args.resume) for label, spec in specs.items()}
    # Every checkpoint is checked: only now change the run directory (a rejected resume leaves it as it was).
    for spec in specs.values():
        checkpoint_path, metrics_path, evals_path = run_files(spec.run_dir)
        if not (args.resume and os.path.exists(checkpoint_path)):
            for p in (metrics_path, evals_path):
                if os.path.exists(p):
                    os.unlink(p)
    evaluation.write_json(os.path.join(args.out, "config.json"), {
        "argv": sys.argv if argv is None else list(argv), "config": setup.config.to_dict(),
        "lessons": setup.lessons.to_dict(), "residual_scale": setup.residual_scale,
        "task_kwargs": args.task_kwargs, "layout": args.layout,
        "init_from": {"path": init.get("init_from", _previous_init_path(args.out)), "sha256": init["init_digest"]}
        if init else None,
        "plans": {k: format_plan(v) for k, v in setup.run_plans.items()}, "seed": args.seed})
    return specs, runs


def _workers(args) -> int:
    return args.workers if args.stop_at_step is None else 1  # the kill hook raises in this process


def _parallel(args, specs) -> bool:
    return _workers(args) > 1 and len(specs) > 1


def train_all(args, setup: _Setup, specs: dict, runs: dict):
    """Train and evaluate every run, here or one per worker, and the lookup; (outcomes, lookup reports)."""
    total = sum(l.steps for l in setup.plan)
    eval_every = args.eval_every or max(1, total // 6)
    eval_at = sorted(set(_boundaries(setup.plan)) | set(range(eval_every, total + 1, eval_every)))
    job = RunJob(domain=setup.domain, heldout_task=setup.heldout_task, track_task=setup.track_task,
                 eval_at=tuple(eval_at), num_eval_targets=args.num_eval_targets,
                 final_eval_targets=args.final_eval_targets, out_eval=os.path.join(args.out, "evaluation"),
                 record=not args.no_rerun, stop_at_step=args.stop_at_step)
    episodes = evaluation.episode_count(setup.domain, final_targets(job), setup.track_task)
    progress = Progress(sum(spec.total_steps for spec in specs.values()), enabled=not args.quiet,
                        evaluations=episodes * (len(specs) + setup.domain.is_arm))  # the lookup's too
    progress.skip(sum(r.loop.env_steps for r in runs.values()))
    stopped = True
    try:
        if _parallel(args, specs):  # the lookup's evaluation joins the workers' queue (a run's core once it is done)
            jobs = {**specs, LOOKUP_LABEL: LookupSpec()} if setup.domain.is_arm else specs
            outcomes = _train_in_parallel(jobs, job, progress, _workers(args))
            lookup = outcomes.pop(LOOKUP_LABEL)["reports"] if setup.domain.is_arm else None
        else:
            outcomes = {label: train_and_evaluate(run, job, progress) for label, run in runs.items()}
            lookup = LookupSpec().evaluate(job, progress)
        stopped = False
    finally:
        progress.close(cleared=stopped)
    return outcomes, lookup


def _boundaries(plan) -> list:
    return list(np.cumsum([l.steps for l in plan]))


def lesson_end_evaluations(records: list, plan) -> dict:
    """``{"heldout_after_lessonK": summary}``: the evaluation on every held-out target at the end of
    each lesson of ``plan`` but the last, from the run's evals.jsonl (the last record of each)."""
    names = {int(end): f"heldout_after_{lesson.task}" for end, lesson in zip(_boundaries(plan)[:-1], plan)}
    return {names[r["env_steps"]]: r["summary"] for r in records
            if r.get("lesson_end") and r["env_steps"] in names}


def report(args, setup: _Setup, specs: dict, outcomes: dict, lookup) -> dict:
    """Figures, the training curves' recording and summary.json (printed); returns the summary."""
    finals = {label: o["reports"] for label, o in outcomes.items()}
    if lookup is not None:  # the no-learning bar, beside the agents
        finals["lookup"] = lookup
    # written by whoever trained, here or in a worker
    metrics = {label: read_jsonl(run_files(spec.run_dir)[1]) for label, spec in specs.items()}
    evals = {label: read_jsonl(run_files(spec.run_dir)[2]) for label, spec in specs.items()}
    if not args.no_figures:
        from agents.robostrich import figures
        os.makedirs(os.path.join(args.out, "figures"), exist_ok=True)
        figures.plot_learning_curves(metrics, evals, os.path.join(args.out, "figures", "learning_curves.png"),
                                     lesson_boundaries=_boundaries(setup.plan)[:-1],
                                     baselines={"lookup": lookup["heldout"]["summary"]} if lookup else None)
        if setup.track_task:
            figures.plot_track({l: f["track"] for l, f in finals.items()},
                               os.path.join(args.out, "figures", "track.png"))
    if not args.no_rerun:
        from agents.robostrich import recording
        recording.log_training_curves(os.path.join(args.out, "training.rrd"), metrics, evals)
    summary = {"runs": {label: {k: f[k]["summary"] for k in f} for label, f in finals.items()},
               "lesson_ends": {label: lesson_end_evaluations(evals[label], spec.plan) for label, spec in specs.items()},
               "env_steps": {label: o["env_steps"] for label, o in outcomes.items()},
               "updates": {label: o["updates"] for label, o in outcomes.items()},
               "timings": {label: o["timing"] for label, o in outcomes.items() if o["timing"]}}
    evaluation.write_json(os.path.join(args.out, "summary.json"), summary)
    print_summary(args.out, summary)
    return summary


def print_summary(out: str, summary: dict) -> None:
    """The run's results in a few lines (evaluation.summary_lines; the JSON is in summary.json) and where they are."""
    print("\n".join(evaluation.summary_lines(summary["runs"])))
    print(f"wrote {out}/: summary.json, evaluation/, checkpoints and records per run"
          + (", figures/" if os.path.isdir(os.path.join(out, "figures")) else "")
          + (", training.rrd" if os.path.exists(os.path.join(out, "training.rrd")) else ""))


def finished_summary(args, setup: _Setup) -> Optional[dict]:
    """On --resume, the summary.json of a run whose every run has trained its whole plan; else None."""
    path = os.path.join(args.out, "summary.json")
    if not args.resume or not os.path.exists(path):
        return None
    summary = parsing.read_json(path)
    planned = {label: sum(l.steps for l in plan) for label, plan in setup.run_plans.items()}
    return summary if summary.get("env_steps") == planned else None


def cli(argv=None) -> int:
    """Console script `robostrich-train`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-train", argv)


if __name__ == "__main__":
    sys.exit(cli())
