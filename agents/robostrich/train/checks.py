"""robostrich-train's input checks: every name and value of the command line resolved and checked
(`prepare`) before anything is built, each problem one line naming its flag."""
import argparse
import dataclasses
import json
from typing import Optional

from agents.curriculum import Lesson, LessonSettings
from agents.robostrich.evaluate import evaluation
from agents.robostrich.domains import Domain
from agents.robostrich.train.main_job import config_from_args, plan_from_args, resolve_layout, resolve_task_kwargs, with_flags
from agents.robostrich.domain_run import check_lesson_names
from agents.robostrich.run_spec import RunSpec
from agents.replay import ObservationFlattener
from agents.sac.config import SACConfig
from robostrich_suite import parsing
from robostrich_suite.tasks import perturbations


def json_object(text: str) -> dict:
    try:
        value = parsing.loads_json(text)
    except ValueError as error:  # torn, or nested too deeply
        raise argparse.ArgumentTypeError(str(error)) from None
    if not isinstance(value, dict):
        raise argparse.ArgumentTypeError(f"expected a JSON object, got {type(value).__name__}")
    return value


def randomize_scales(text: str) -> dict:
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


def check_task_kwargs(plan, layout, task_kwargs: dict, config: Optional[SACConfig] = None) -> None:
    """Build each lesson's environment once with ``task_kwargs``, so that an unknown option or a
    bad value is a one-line error naming --task-kwargs now, not a worker's traceback later; and
    ``config``'s fine inputs must name entries each lesson observes (--fine-inputs)."""
    for domain_name, task in dict.fromkeys((lesson.domain, lesson.task) for lesson in plan):
        try:
            env = Domain(domain_name, layout).make_environment(task, 0, **task_kwargs)
        except (TypeError, ValueError) as error:
            raise ValueError(f"--task-kwargs {json.dumps(task_kwargs, default=str)} does not suit "
                             f"{domain_name}/{task}: {error}") from error
        flattener = ObservationFlattener(env.observation_spec())
        env.close()
        if config is not None:
            try:
                config.fine_input_entries(flattener.keys, flattener.sizes)
            except ValueError as error:
                raise ValueError(f"{with_flags(str(error))} in {domain_name}/{task}") from None


def check_residual_scale(scale: float, config: SACConfig) -> float:
    """--residual-scale in [0, 2] and not with hindsight goals (a new goal changes the lookup's action)."""
    if not 0.0 <= scale <= 2.0:
        raise ValueError(f"--residual-scale must be in [0, 2] (0 = no residual), got {scale}")
    if scale > 0 and config.her_ratio > 0:
        raise ValueError("--residual-scale and --her-ratio do not mix: a relabelled goal changes the lookup's "
                         "action, so the stored residual would no longer mean what it did (add --her-ratio 0)")
    return float(scale)


def check_goal_free_terms(task_kwargs: dict, config: SACConfig) -> None:
    """The reward's head-speed term depends on the goal in a way ``goal_reward`` does not compute:
    rewards the replay recomputes for goals (hindsight, ``relabel_rewards``) would silently drop it,
    so it needs both off. (The action-change term no goal changes: the replay keeps it.)"""
    weights = task_kwargs.get("weights")
    for term in ("head_vertical_speed",):
        weight = weights.get(term, 0) if isinstance(weights, dict) else getattr(weights, term, 0)
        if weight and (config.relabel_rewards or config.her_ratio > 0):
            raise ValueError(f"--task-kwargs weights.{term} needs the replay to keep the rewards the task "
                             "gave (recomputing them for goals drops the term): add --no-relabel-rewards --her-ratio 0")


@dataclasses.dataclass
class TrainingSetup:
    """What the command line resolves to before anything is built."""
    config: SACConfig
    lessons: LessonSettings
    residual_scale: float
    plan: list
    domain: Domain
    heldout_task: str
    track_task: Optional[str]
    run_plans: dict

    def run_spec(self, args, label: str, init_from: Optional[str] = None) -> RunSpec:
        """The run ``label`` (curriculum, baseline) of this command line; ``init_from``: the content
        hash of the checkpoint its learner starts from."""
        return RunSpec(self.run_plans[label], self.config, args.seed, self.lessons, args.task_kwargs, args.layout,
                       init_from, self.residual_scale)


def prepare(args, argv) -> TrainingSetup:
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
    check_task_kwargs(plan, args.layout, args.task_kwargs, config)
    domain = dataclasses.replace(domain, sent_actions=args.task_kwargs.get("observe_sent_actions", 0))
    check_goal_free_terms(args.task_kwargs, config)
    try:
        check_lesson_names(plan, config, lessons, args.layout)
    except ValueError as error:  # it names the settings' fields; the user typed flags
        raise ValueError(with_flags(str(error))) from None
    heldout_task = evaluation.check_heldout_task(domain, args.heldout_task or domain.heldout_task(final.task))
    track_task = evaluation.check_track_task(domain, args.track_task)
    run_plans = {"curriculum": plan}
    if args.baseline:
        run_plans["baseline"] = [Lesson(final.domain, final.task, sum(l.steps for l in plan))]
    return TrainingSetup(config, lessons, residual_scale, plan, domain, heldout_task, track_task, run_plans)
