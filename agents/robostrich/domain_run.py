"""A curriculum run over named domains: the arm's tasks (with a tendon layout and task options)
or dm_control's, with the lookup as the residual policy's base and the head's errors in every
episode's record."""
from typing import Callable, Optional, Sequence

from agents import curriculum
from agents.curriculum import Lesson, LessonSettings
from agents.robostrich import environment_state
from agents.robostrich.domains import as_domain, Domain
from agents.robostrich.lookup import LookupPolicy
from agents.sac.config import SACConfig
from robostrich_suite import atomic_files
from robostrich_suite.tasks.measurement import measure

DEFAULT_DOMAIN = "robostrich"
# What changes with the lesson unless a run says otherwise (robostrich-train's defaults too): hindsight
# goals in lesson 1 only (without them some seeds never learn the upper workspace; in lessons 2-3
# they hurt: docs/log/learning.md#hindsight-goals-in-lesson-1-only-every-seed-learns-the-whole-workspace-2026-11-30).
DEFAULT_LESSONS = LessonSettings(her_lessons=("lesson1",))


def parse_plan(text: str, default_domain: str = DEFAULT_DOMAIN):
    """'lesson1:50000,lesson2:50000' or 'point_mass/easy:2000' -> [Lesson, ...] (the arm by default).
    A step count must be whole ('5e4' is, '300.9' is refused rather than cut to 300)."""
    for item in filter(None, (s.strip() for s in text.split(","))):
        steps = item.rpartition(":")[2]
        try:
            whole = float(steps).is_integer()
        except ValueError:
            continue  # not a number: curriculum.parse_plan names the lesson
        if not whole:
            raise ValueError(f"lesson {item!r}: {steps} is not a whole number of steps")
    return curriculum.parse_plan(text, default_domain)


def _is_arm_plan(plan) -> bool:
    return bool(plan) and all(as_domain(lesson.domain).is_arm for lesson in plan)


def named_layout(layout: Optional[str], plan) -> Optional[str]:
    """The tendon layout a run on ``plan`` trains, by name: ``layout``, or the tasks' default on
    the arm domains (None off them)."""
    if layout is not None or not _is_arm_plan(plan):
        return layout
    return as_domain(plan[-1].domain).layout  # the arm domain names its default


def identity_extra(plan, task_kwargs: Optional[dict] = None, layout: Optional[str] = None,
                   init_from: Optional[str] = None, residual_scale: float = 0.0) -> dict:
    """What a run's fingerprint holds beside config, lesson settings, plan and seed: the task options,
    the layout by name, ``init_from`` (the content hash of the checkpoint the run started from,
    agents/robostrich/train/transfer.py) and a residual policy's scale."""
    extra = {}
    if residual_scale:
        extra["residual_scale"] = float(residual_scale)
    if task_kwargs:
        extra["task_kwargs"] = dict(task_kwargs)
    layout = named_layout(layout, plan)
    if layout is not None:
        extra["layout"] = layout
    if init_from is not None:
        extra["init_from"] = init_from
    return extra


def run_identity(plan: Sequence[Lesson], config: SACConfig, seed: int, lessons: LessonSettings = DEFAULT_LESSONS,
                 task_kwargs: Optional[dict] = None, layout: Optional[str] = None, init_from: Optional[str] = None,
                 residual_scale: float = 0.0) -> dict:
    """The fingerprint part known before a run is built (robostrich-train checks a resume against it)."""
    return curriculum.run_identity(plan, config, seed, lessons,
                                   identity_extra(plan, task_kwargs, layout, init_from, residual_scale))


def current_fingerprint(stored: dict) -> dict:
    """curriculum.current_fingerprint, with her_level_goals on (a SACConfig field until 2026-12-05)
    read as what it became: on an arm plan the reaching tasks' option hindsight_level_goals,
    elsewhere nothing (dm_control's tasks have no goals)."""
    config = stored.get("config")
    if isinstance(config, dict) and config.get("her_level_goals") is True and isinstance(stored.get("plan"), str):
        stored = {**stored, "config": {k: v for k, v in config.items() if k != "her_level_goals"}}
        try:
            arm = _is_arm_plan(parse_plan(stored["plan"]))
        except ValueError:  # a plan this version cannot read: left for the fingerprint check to name
            arm = False
        if arm:
            stored["task_kwargs"] = {**(stored.get("task_kwargs") or {}), "hindsight_level_goals": True}
    return curriculum.current_fingerprint(stored)


def check_lesson_names(plan, config: SACConfig, lessons: LessonSettings, layout: Optional[str] = None) -> None:
    """ValueError naming the field if a per-lesson setting names a task the plan's domains lack (dm_control's
    tasks have no goal reward, so HER's lessons are checked on the arm only). An unknown `layout`, or
    one on a dm_control plan, fails here too."""
    arm_domains = {d for d in (as_domain(lesson.domain, layout) for lesson in plan) if d.is_arm}
    curriculum.check_lesson_names(plan, config, lessons, [t for d in arm_domains for t in d.tasks()], bool(arm_domains))


def episode_metrics(env) -> dict:
    """What an episode's record in metrics.jsonl gets from its last state (the loop's
    ``episode_probe``): the task's measurement's errors (the attitude's size) and success."""
    measured = measure(env)
    return {"position_error": measured.position_error, "attitude_error": abs(measured.attitude_error),
            "success": measured.is_success}


class DomainRun(curriculum.CurriculumRun):
    """A CurriculumRun whose lessons name domains of agents/robostrich/domains.py."""

    def __init__(self, plan: Sequence[Lesson], config: SACConfig, seed: int, run_dir: str,
                 checkpoint_every: int = 10_000, env_factory: Optional[Callable] = None, name: str = "run",
                 task_kwargs: Optional[dict] = None, layout: Optional[str] = None,
                 init_from: Optional[str] = None, keep_lesson_checkpoints: bool = False,
                 lessons: LessonSettings = DEFAULT_LESSONS, residual_scale: float = 0.0):
        """``task_kwargs`` go to every lesson's task (e.g. eq. 10's ``weights``); ``layout`` names a
        built-in tendon layout of the arm domains (its own targets come with it); ``init_from`` is the
        content hash of the checkpoint whose learner this run starts from (transfer.initialize puts
        it there); ``env_factory(domain, task, seed, **task_kwargs)``, if given, builds a lesson's environment
        instead of the domain's own ``make_environment``;
        ``residual_scale`` > 0 trains a residual on the first lesson's lookup."""
        check_lesson_names(plan, config, lessons, layout)  # and an unknown layout fails here, not mid-run
        self.task_kwargs = dict(task_kwargs or {})
        self.layout = layout
        self.init_from = init_from
        self.env_factory = env_factory
        self.residual_scale = float(residual_scale)
        super().__init__(plan, config, seed, run_dir, self._make_lesson_environment, checkpoint_every, name,
                         lessons=lessons, residual=self._residual(plan), episode_probe=episode_metrics,
                         keep_lesson_checkpoints=keep_lesson_checkpoints, episode_state=environment_state)

    def save_checkpoint(self, path: Optional[str] = None):
        """CurriculumRun's, with a failed write (a full disk) naming the checkpoint."""
        path = path or self.checkpoint_path
        with atomic_files.naming(path, only_unnamed=True):
            super().save_checkpoint(path)

    def extra_identity(self) -> dict:
        """The task options, the layout and ``init_from`` (which transfer.initialize may set after building)."""
        return identity_extra(self.plan, self.task_kwargs, self.layout, self.init_from, self.residual_scale)

    current_fingerprint = staticmethod(current_fingerprint)

    def _make_lesson_environment(self, lesson: Lesson, seed: int):
        if self.env_factory is None:
            return self.domain(lesson).make_environment(lesson.task, seed, **self.task_kwargs)
        return self.env_factory(self.domain(lesson), lesson.task, seed, **self.task_kwargs)

    def _residual(self, plan):
        """(base policy factory, scale) of a residual on the first lesson's lookup, or None."""
        if self.residual_scale <= 0:
            return None
        table = self.domain(plan[0]).lookup_table()
        return (lambda flattener: LookupPolicy(flattener, table)), self.residual_scale

    def domain(self, lesson: Optional[Lesson] = None):
        """The Domain of `lesson` (default: the last), with this run's layout."""
        return Domain((lesson or self.plan[-1]).domain, self.layout, self.task_kwargs.get("observe_sent_actions", 0))
