"""A run of the agent described once: what makes two runs the same run, which is what a checkpoint's
fingerprint holds beside the learner's input layout, and the one reading of an older fingerprint as
this version writes it. Training builds a run from a ``RunSpec``; resuming, evaluating and starting
from another run's checkpoint read one back with ``RunSpec.from_fingerprint``."""
import dataclasses
from typing import Mapping, Optional, Tuple

from agents import curriculum
from agents.curriculum import Lesson, LessonSettings
from agents.robostrich.domains import as_domain
from agents.sac.config import SACConfig

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


def is_arm_plan(plan) -> bool:
    return bool(plan) and all(as_domain(lesson.domain).is_arm for lesson in plan)


def named_layout(layout: Optional[str], plan) -> Optional[str]:
    """The tendon layout a run on ``plan`` trains, by name: ``layout``, or the tasks' default on
    the arm domains (None off them)."""
    if layout is not None or not is_arm_plan(plan):
        return layout
    return as_domain(plan[-1].domain).layout  # the arm domain names its default


@dataclasses.dataclass(frozen=True)
class RunSpec:
    """The lesson plan, the agent's settings, the seed and what changes with the lesson;
    ``task_kwargs`` go to every lesson's task (e.g. eq. 10's ``weights``); ``layout`` names a
    built-in tendon layout of the arm domains (its own targets come with it); ``init_from`` is the
    content hash of the checkpoint whose learner the run starts from (transfer.initialize sets it);
    ``residual_scale`` > 0 trains a residual on the first lesson's lookup."""
    plan: Tuple[Lesson, ...]
    config: SACConfig
    seed: int
    lessons: LessonSettings = DEFAULT_LESSONS
    task_kwargs: Optional[Mapping] = None  # kept as a dict of its own (picklable, for a worker)
    layout: Optional[str] = None
    init_from: Optional[str] = None
    residual_scale: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "plan", tuple(self.plan))
        object.__setattr__(self, "layout", named_layout(self.layout, self.plan))  # the arm's default, by name
        object.__setattr__(self, "task_kwargs", dict(self.task_kwargs or {}))
        object.__setattr__(self, "residual_scale", float(self.residual_scale))

    def identity(self) -> dict:
        """The fingerprint part known before the run is built (a resume is checked against it)."""
        return curriculum.run_identity(self.plan, self.config, self.seed, self.lessons, self.extra_identity())

    def extra_identity(self) -> dict:
        """What the fingerprint holds beside config, lesson settings, plan and seed: the task options,
        the layout by name, ``init_from`` and a residual policy's scale."""
        extra = {}
        if self.residual_scale:
            extra["residual_scale"] = self.residual_scale
        if self.task_kwargs:
            extra["task_kwargs"] = dict(self.task_kwargs)
        if self.layout is not None:
            extra["layout"] = self.layout
        if self.init_from is not None:
            extra["init_from"] = self.init_from
        return extra

    @classmethod
    def from_fingerprint(cls, stored: dict) -> "RunSpec":
        """The run a checkpoint's fingerprint describes, in whatever format it was written
        (``migrate``); ValueError or KeyError where it holds no run."""
        fingerprint = migrate(stored)
        return cls(parse_plan(fingerprint["plan"]), SACConfig.from_dict(fingerprint["config"]), fingerprint["seed"],
                   LessonSettings.from_dict(fingerprint["lessons"]), fingerprint.get("task_kwargs"),
                   fingerprint.get("layout"), fingerprint.get("init_from"), fingerprint.get("residual_scale", 0.0))


def migrate(stored: dict) -> dict:
    """A checkpoint's fingerprint as this version writes it for the same run, whatever version wrote
    it; every reader of a stored fingerprint goes through here. The agent's settings as
    curriculum.current_fingerprint reads them (SACConfig's removed and added fields), and
    her_level_goals on (a SACConfig field until 2026-12-05) as what it became: on an arm plan the
    reaching tasks' option hindsight_level_goals, elsewhere nothing (dm_control's tasks have no goals)."""
    config = stored.get("config")
    if isinstance(config, dict) and config.get("her_level_goals") is True and isinstance(stored.get("plan"), str):
        stored = {**stored, "config": {k: v for k, v in config.items() if k != "her_level_goals"}}
        try:
            arm = is_arm_plan(parse_plan(stored["plan"]))
        except ValueError:  # a plan this version cannot read: left for the fingerprint check to name
            arm = False
        if arm:
            stored["task_kwargs"] = {**(stored.get("task_kwargs") or {}), "hindsight_level_goals": True}
    return curriculum.current_fingerprint(stored)
