"""A curriculum run over named domains: the arm's tasks (with a tendon layout and task options)
or dm_control's, with the lookup as the residual policy's base and the head's errors in every
episode's record."""
from typing import Callable, Optional

from agents import curriculum
from agents.curriculum import Lesson, LessonSettings
from agents.robostrich import environment_state
from agents.robostrich.domains import as_domain, Domain
from agents.robostrich.lookup import LookupPolicy
from agents.robostrich.run_spec import RunSpec, migrate
from agents.sac.config import SACConfig
from robostrich_suite import atomic_files
from robostrich_suite.tasks.measurement import measure


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

    def __init__(self, spec: RunSpec, run_dir: str, checkpoint_every: int = 10_000,
                 env_factory: Optional[Callable] = None, name: str = "run", keep_lesson_checkpoints: bool = False):
        """``spec``: the run (agents/robostrich/run_spec.py); ``env_factory(domain, task, seed,
        **task_kwargs)``, if given, builds a lesson's environment instead of the domain's own
        ``make_environment``."""
        check_lesson_names(spec.plan, spec.config, spec.lessons, spec.layout)  # and an unknown layout, not mid-run
        self.spec = spec
        self.env_factory = env_factory
        super().__init__(spec.plan, spec.config, spec.seed, run_dir, self._make_lesson_environment, checkpoint_every,
                         name, lessons=spec.lessons, residual=self._residual(spec.plan), episode_probe=episode_metrics,
                         keep_lesson_checkpoints=keep_lesson_checkpoints, episode_state=environment_state)

    @property
    def task_kwargs(self) -> dict:
        return self.spec.task_kwargs

    @property
    def layout(self) -> Optional[str]:
        return self.spec.layout

    @property
    def residual_scale(self) -> float:
        return self.spec.residual_scale

    def save_checkpoint(self, path: Optional[str] = None):
        """CurriculumRun's, with a failed write (a full disk) naming the checkpoint."""
        path = path or self.checkpoint_path
        with atomic_files.naming(path, only_unnamed=True):
            super().save_checkpoint(path)

    def extra_identity(self) -> dict:
        """The spec's (whose ``init_from`` transfer.initialize may set after building)."""
        return self.spec.extra_identity()

    current_fingerprint = staticmethod(migrate)

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
