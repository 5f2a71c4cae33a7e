"""The main job's defaults: its budget and lesson shares per domain, the agent's settings, the per-lesson
settings and task options it trains with, and how the command line's plan and configuration resolve over them
(robostrich-train reads them; sweeps, peers and layouts start from them)."""
from typing import Optional

from agents import config_flags
from agents.curriculum import Lesson, LessonSettings
from agents.robostrich.domains import Domain
from agents.robostrich.run_spec import parse_plan
from agents.sac.config import SACConfig
from robostrich_suite import cli as cli_lib
from robostrich_suite.model import layouts

# The agent's settings robostrich-train trains with on every domain (its flags' defaults), each measured
# on the arm (docs/training.md#the-main-job): a decision every control step, 64x64 networks at lr 1e-3
# with layer-normalised critics, 1k random transitions first, 4 updates every 4 transitions, a low
# initial temperature, a target entropy of -2 per action, hindsight goals (lessons: DEFAULT_LESSONS)
# and rewards recomputed for the current lesson, the pre-tanh penalty and the policy's moving
# average. SACConfig() is the algorithm's neutral defaults; --paper-sac gives SACConfig.paper_sac().
MAIN_JOB_SAC = SACConfig(batch_size=64, learning_rate=1e-3, target_entropy_per_action=-2.0, init_temperature=0.01,
                         hidden_sizes=(64, 64), min_replay_size=1_000, updates_per_call=4, env_steps_per_call=4,
                         critic_layer_norm=True, her_ratio=0.5, relabel_rewards=True, pre_tanh_penalty=0.1,
                         policy_average=1e-4, policy_average_fraction=0.1)
DEFAULT_TOTAL_STEPS = 480_000  # per run, split evenly over the lessons; the two runs train side by side
# The main job on the frame arm: 200k control steps, lessons 1-2 keep 53k each and lesson 3, where the
# policy refines its reach from moving starts, gets the longest share; every lesson trains with a
# narrower policy Gaussian (target entropy -3 per action instead of -2: about 1 % of an input's range
# instead of 3 %, where a held input 1 % off already costs a target) at twice the step size (2e-3), and
# the networks also read fine inputs of the two errors the task is judged by (SACConfig.fine_inputs):
# tanh(100 x the error to the target in metres) and tanh(30 x the attitude's in radians), so that
# millimetres and tenths of a degree read as inputs of order one
# (docs/log/learning.md#fine-inputs-of-the-errors-alone-the-main-job-in-a-third-of-the-steps-2026-12-05).
# On the quadruped (Algorithm 1 as the paper ran it) lessons 1-3 on the standing quadruped get 600k
# with lesson 3 alone narrowed, then lesson 4 (trotting, the trunk height changing) 150k more.
MAIN_JOB_STEPS = {"robostrich": 200_000, "robostrich_a1": 750_000}
MAIN_JOB_LESSON_SHARES = {"robostrich": (4, 4, 7), "robostrich_a1": (16, 16, 28, 15)}  # of the curriculum, in order
# Lesson 4 starts with an empty replay: continuing on the standing lessons' transitions, its own
# success fell while it trained, and with it the standing targets
# (docs/log/quadruped.md#2026-12-03-hindsight-goals-were-off-lesson-4-after-them-the-head-speed-term).
_NARROW = {"exploration_target_entropy_per_action": -3.0}
# Per domain, SACConfig and LessonSettings fields over MAIN_JOB_SAC and DEFAULT_LESSONS.
MAIN_JOB_BY_DOMAIN = {"robostrich": {**_NARROW, "exploration_lessons": ("lesson1", "lesson2", "lesson3"),
                                     "learning_rate": 2e-3, "fine_inputs": ("to_target=100", "attitude_error=30")},
                      "robostrich_a1": {**_NARROW, "exploration_lessons": ("lesson3",),
                                        "fresh_replay_lessons": ("lesson4",)}}
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
# "target_sampling": "uniform", "fixed_stored_starts": 0, "target_between": 0}' gives the paper's
# eq. 10, draw and starts. Evaluation keeps the task's defaults.
DEFAULT_ARM_TASK_KWARGS = {"weights": {"position_precision": 1.0, "attitude_precision": 0.5},
                           "target_sampling": "failures", "fixed_stored_starts": 0.25}
# The same with lessons 1-2 starting fixed, for arms whose stored poses (a layout's lookup table)
# are not shipped: the candidate arms of robostrich-layouts --train.
FIXED_START_ARM_TASK_KWARGS = {**DEFAULT_ARM_TASK_KWARGS, "fixed_stored_starts": 0.0}


# On the frame each drawn training target also moves a uniform share of the way towards one of its 4
# nearest stored poses (Reach target_between), so that training meets the level poses between the
# stored ones, where a researcher's own targets lie, not only the list
# (docs/log/learning.md#targets-between-the-stored-poses-adopted-2026-12-07). Not measured on the
# quadruped, which keeps the list.
FRAME_TASK_KWARGS = {"target_between": 4}

# On the quadruped a quarter of lesson 4's episodes stand (the standing lessons rehearsed): trained
# on trotting alone, the policy could lose standing targets it had held after lesson 3
# (docs/log/quadruped.md#2026-12-04-lesson-4-rehearses-standing-what-limits-the-heads-vertical-speed).
# The standing lessons ignore the option.
QUADRUPED_TASK_KWARGS = {"standing_share": 0.25}

positive_int = cli_lib.whole_number(1, MAX_TOTAL_STEPS)  # control steps


def default_task_kwargs(domain: Domain) -> dict:
    """The main job's task arguments on `domain` (none off the arm): the arm's on the frame and on
    the quadruped, where the arm holds the stored poses as on the frame; then targets between the
    stored poses on the frame, lesson 4's rehearsal on the quadruped."""
    if not domain.is_arm:
        return {}
    return {**DEFAULT_ARM_TASK_KWARGS, **(QUADRUPED_TASK_KWARGS if domain.on_quadruped else FRAME_TASK_KWARGS)}


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


def plan_from_args(args):
    """The curriculum's lessons from --plan, or from --lessons and --steps over the domain's shares."""
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


def config_from_args(args, argv=None, cls=SACConfig):
    """The ``cls`` (SACConfig or LessonSettings) the flags give (their defaults: MAIN_JOB_SAC,
    DEFAULT_LESSONS): under --paper-sac the paper's (nothing per lesson), else the main job's
    settings on its domain, explicit flags on top."""
    values = config_flags.parsed_values(args, cls)
    explicit = config_flags.explicit_fields(argv, cls)
    if getattr(args, "paper_sac", False):
        paper = SACConfig.paper_sac() if cls is SACConfig else LessonSettings()
        values = {k: (v if k in explicit else getattr(paper, k)) for k, v in values.items()}
    else:  # the main job's settings on its domain, under the flags given
        values.update({k: v for k, v in MAIN_JOB_BY_DOMAIN.get(getattr(args, "domain", None), {}).items()
                       if k not in explicit and k in values})
    try:
        return cls(**values)
    except ValueError as error:  # SACConfig names its fields; the user typed flags
        raise ValueError(with_flags(str(error))) from None


def with_flags(message: str) -> str:
    """``message`` with every SACConfig and LessonSettings field name replaced by its flag."""
    return config_flags.with_flags(message, (SACConfig, LessonSettings))
