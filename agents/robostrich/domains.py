"""What the agent layer needs to know about a domain, in one place.

The curriculum, the evaluation and the training CLI ask a `Domain` for an
environment, the held-out targets, the lookup table and which evaluations
exist, instead of testing domain names themselves.  Every domain in
``robostrich_suite.TASKS_BY_DOMAIN`` is an arm domain (``robostrich`` on the
frame, ``robostrich_a1`` on the quadruped, targets in its trunk frame); any
other name is a dm_control suite domain, scored by episode returns.

An arm domain may also observe the actions it sent (``sent_actions`` = k, the task option
``observe_sent_actions``): a policy trained so reads an observation the others lack, so every
environment made for it, in training, evaluation, play and the robustness tool, must carry it.

An arm domain may name a built-in tendon layout (``robostrich_suite.model.layouts``):
its lessons then use that layout and its shipped level poses, and the
held-out targets and the lookup table come from the same file, so an agent
trained on ``antagonist_pairs`` is judged on that layout's targets.
"""
import dataclasses
from typing import Optional, Tuple

import numpy as np
import robostrich_suite
from agents.robostrich.lookup import lookup_table, nearest
from robostrich_suite import targets
from robostrich_suite.model import layouts
from robostrich_suite.studies import new_targets
from robostrich_suite.tasks import lessons, options, reach
from robostrich_suite.tasks.track import default_track_targets

TRACK_TASK = "track"  # the name --track-task asks for by default (the frame arm's task tagged "track")


def arm_domains() -> Tuple[str, ...]:
    return tuple(robostrich_suite.TASKS_BY_DOMAIN)


@dataclasses.dataclass(frozen=True)
class Domain:
    """A domain name plus, on the arm, a built-in tendon layout (default: the tasks' own) and the
    number of sent actions its observation holds (module doc)."""
    name: str
    layout: Optional[str] = None
    sent_actions: int = 0

    def __post_init__(self):
        if self.layout is None and self.is_arm:  # the tasks' own routing, by name
            object.__setattr__(self, "layout", layouts.DEFAULT)
        if self.layout is not None:
            if not self.is_arm:
                raise ValueError(f"--layout applies to the arm domains {list(arm_domains())}, "
                                 f"not to {self.name!r}")
            layouts.target_file(self.layout)  # names the built-in layouts, or those that ship targets
        if self.sent_actions:
            if not self.is_arm:
                raise ValueError(f"observe_sent_actions applies to the arm domains {list(arm_domains())}, "
                                 f"not to {self.name!r}")
            object.__setattr__(self, "sent_actions", options.whole(
                "observe_sent_actions", self.sent_actions, 0, reach.MAX_SENT_ACTIONS, "a whole number of control steps"))

    # -- what kind of domain -----------------------------------------------------------------
    @property
    def is_arm(self) -> bool:
        """A robostrich_suite domain: head errors, held-out targets, the lookup baseline."""
        return self.name in arm_domains()

    def tasks(self) -> Tuple[str, ...]:
        if self.is_arm:
            return tuple(robostrich_suite.TASKS_BY_DOMAIN[self.name])
        from dm_control import suite
        return tuple(task for domain, task in suite.ALL_TASKS if domain == self.name)

    def curriculum(self) -> Tuple[str, ...]:
        """The lessons of Algorithm 1 on this domain, in order (its tasks tagged ``curriculum``):
        lessons 1-3 on the frame; lessons 1-4 on the quadruped."""
        if not self.is_arm:
            raise ValueError(f"{self.name!r} is not a robostrich_suite domain and has no curriculum: "
                             "give its tasks with --lessons or --plan")
        return tuple(task for domain, task in robostrich_suite.CURRICULUM_TASKS if domain == self.name)

    def check_task(self, task: str) -> None:
        """ValueError naming the problem if this domain has no task `task`."""
        tasks = self.tasks()
        if not tasks:
            from dm_control import suite
            raise ValueError(f"unknown domain {self.name!r}: robostrich_suite has {list(arm_domains())}, "
                             f"dm_control.suite has {sorted({d for d, _ in suite.ALL_TASKS})}")
        if task not in tasks:
            raise ValueError(f"domain {self.name!r} has no task {task!r}; its tasks are {list(tasks)}")

    @property
    def on_quadruped(self) -> bool:
        return self.is_arm and robostrich_suite.mount(self.name) == "quadruped"

    def tagged(self, tag: str) -> Tuple[str, ...]:
        """This arm domain's tasks with ``tag`` (robostrich_suite.tasks_tagged); none off the arm."""
        return robostrich_suite.tasks_tagged(self.name, tag) if self.is_arm else ()

    # -- environments ------------------------------------------------------------------------
    def target_file(self):
        """The layout's level-pose target file: its training, held-out and new targets, its lookup table."""
        return layouts.target_file(self.layout)

    def _to_domain_frame(self, frame_targets) -> np.ndarray:
        """Targets of the frame arm in this domain's coordinates (the trunk frame on the quadruped)."""
        return np.asarray(robostrich_suite.targets_from_frame(self.name, np.asarray(frame_targets, np.float64)),
                          np.float64)

    def layout_kwargs(self, task: str) -> dict:
        """The task kwargs a layout implies: the layout, and its own training (or `track`) targets."""
        if self.layout is None:
            return {}
        kwargs = {"tendon_layout": layouts.build(self.layout)}
        if task in self.tagged(lessons.TRACK):
            kwargs["targets"] = default_track_targets(self.heldout_targets())
        elif task in self.tagged(lessons.DRAWS_TARGETS):  # head_stabilize and narrow_gap have their own targets
            kwargs["target_pool"] = self._to_domain_frame(targets.training_targets(self.target_file()))
        return kwargs

    def make_environment(self, task: str, seed: int, **task_kwargs):
        """robostrich_suite.load for the arm (with the layout's kwargs), dm_control.suite.load otherwise."""
        task_kwargs = {"random": seed, **self.layout_kwargs(task), **task_kwargs}
        if self.sent_actions:
            task_kwargs.setdefault("observe_sent_actions", self.sent_actions)
        if (self.is_arm and (task_kwargs.get("stored_starts") or task_kwargs.get("fixed_stored_starts"))
                and task_kwargs.get("start_inputs") is None):
            task_kwargs["start_inputs"] = self.stored_start_inputs()
        if self.is_arm:
            return robostrich_suite.load(self.name, task, task_kwargs=task_kwargs)
        from dm_control import suite
        return suite.load(self.name, task, task_kwargs=task_kwargs)

    # -- evaluation --------------------------------------------------------------------------
    def heldout_task(self, final_task: str) -> str:
        """lesson2 on the arm (eq. 10 from the fixed pose, so every target starts alike); else the final task."""
        return self.tagged(lessons.HELDOUT)[0] if self.is_arm else final_task

    def track_task(self, requested: Optional[str] = TRACK_TASK) -> Optional[str]:
        """`requested` where this domain has it (the frame arm's `track`), else None."""
        return requested if requested and self.is_arm and requested in self.tasks() else None

    @property
    def has_moving_starts(self) -> bool:
        return bool(self.tagged(lessons.MOVING_START))

    @property
    def walking_task(self) -> Optional[str]:
        """The task whose held-out targets are reached while the legs walk (the quadruped's lesson 4), else None."""
        return next(iter(self.tagged(lessons.WALKING)), None)

    @property
    def moving_start_task(self) -> str:
        """The task whose episodes continue from where the last ended (moving starts)."""
        return self.tagged(lessons.MOVING_START)[0]

    def heldout_targets(self, num_targets: Optional[int] = None) -> Optional[np.ndarray]:
        """The layout's held-out targets in this domain's frame; None (seeded episodes) off the arm."""
        if not self.is_arm:
            return None
        return self._to_domain_frame(targets.heldout_targets(self.target_file(), num_targets))

    def new_targets(self, count: int, seed: Optional[int] = None) -> Optional[np.ndarray]:
        """``count`` level poses of this layout at least 1 cm from every pose of its target file,
        made by the project's generator with a seed no target file uses (robostrich_suite/studies/
        new_targets.py; made once, then cached), in this domain's frame; None off the arm."""
        if not self.is_arm:
            return None
        made = new_targets.new_targets(self.target_file(), layouts.build(self.layout),
                                       new_targets.SEED if seed is None else seed, count)
        return self._to_domain_frame(made)

    def lookup_table(self) -> Optional[dict]:
        """The lookup baseline's stored poses for this layout (agents/robostrich/lookup.py), positions in this
        domain's frame; None off the arm."""
        if not self.is_arm:
            return None
        path = self.target_file()
        table = lookup_table(targets.level_head_poses(path), targets.heldout_targets(path))
        table["head_position"] = self._to_domain_frame(table["head_position"])
        return table

    def moving_starts(self, count: int = 3):
        """Start poses of `heldout_moving`: `count` well separated training targets (picked as `track`
        picks its targets) and the stored inputs that hold them (never a held-out pose)."""
        table = self.lookup_table()
        starts = default_track_targets(
            self._to_domain_frame(targets.training_targets(self.target_file())), count)
        return starts, np.stack([table["control"][nearest(table, s)] for s in starts])

    def stored_start_inputs(self, exclusion: float = 0.02) -> np.ndarray:
        """Tendon inputs for lesson 3's ``stored_starts``: the lookup table's (so no held-out
        pose), minus every pose within `exclusion` (m) of the evaluation's moving starts, so the
        moving-start evaluation still starts where training never started."""
        starts, _ = self.moving_starts()
        return lookup_table(self.lookup_table(), heldout=starts, exclusion=exclusion)["control"]

    def describe(self) -> str:
        text = self.name if self.layout is None else f"{self.name} (layout {self.layout})"
        return text + (f", observing {self.sent_actions} sent actions" if self.sent_actions else "")

    def info(self) -> dict:
        """What a policy file or report keeps to rebuild this domain (:func:`domain_of`)."""
        return {"domain": self.name, **({"layout": self.layout} if self.layout else {}),
                **({"observe_sent_actions": self.sent_actions} if self.sent_actions else {})}


def domain_of(info: dict, task_kwargs: Optional[dict] = None) -> Domain:
    """The Domain a policy file's ``info`` (or a report's names) describes; ``task_kwargs`` (a run's)
    may say what it observes."""
    sent = info.get("observe_sent_actions", (task_kwargs or {}).get("observe_sent_actions", 0))
    return Domain(str(info.get("domain", "robostrich")), info.get("layout"), sent)


def as_domain(domain, layout: Optional[str] = None) -> Domain:
    """A `Domain` from a name (or pass one through)."""
    if isinstance(domain, Domain):
        if layout is not None and layout != domain.layout:
            raise ValueError(f"domain {domain.describe()} already names a layout, not {layout!r}")
        return domain
    return Domain(str(domain), layout)
