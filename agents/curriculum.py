"""The curriculum (Algorithm 1): one agent goes through a list of lessons.

Parameters, optimiser states, temperature and replay are never reset between
lessons; only the environment is swapped. A plain-SAC baseline is the same
runner with a one-lesson plan.
"""
import dataclasses
import json
import os
from typing import Callable, ClassVar, List, Optional, Sequence, Tuple

import numpy as np

from agents import checkpoint, trees
from agents.sac.builder import SACBuilder
from agents.sac import state_layout
from agents.sac.config import SACConfig


@dataclasses.dataclass(frozen=True)
class LessonSettings:
    """What changes with the lesson while the agent carries over (Algorithm 1): lessons named by
    their task get hindsight goals, a longer discount, or their own target entropy and correlated
    exploration noise. Empty names: hindsight in every lesson, the rest in none."""
    # Lessons whose batches get the config's her_ratio of hindsight goals (empty: every lesson).
    her_lessons: Tuple[str, ...] = ()
    # Lessons that train with `long_horizon_discount` instead of the config's discount, for
    # manoeuvres that take longer than the discount looks ahead (0.99 at 125 Hz: 0.8 s).
    long_horizon_lessons: Tuple[str, ...] = ()
    long_horizon_discount: float = 0.995
    # Lessons that train toward `exploration_target_entropy_per_action` x |A| instead of the
    # config's target entropy: wider noise for a manoeuvre the policy's narrow noise never tries,
    # or narrower noise where precision matters more than search ...
    exploration_lessons: Tuple[str, ...] = ()
    exploration_target_entropy_per_action: float = -1.0
    # ... and explore there with noise correlated over control steps (AR(1) coefficient per step
    # of the policy Gaussian's standard normal draw; 0 = white noise, as plain SAC).
    exploration_noise_correlation: float = 0.0
    # Lessons that start with an empty replay: where the motion changes so much that the earlier
    # lessons' transitions crowd out the new ones (a walking base after a standing one).
    fresh_replay_lessons: Tuple[str, ...] = ()

    HELP: ClassVar[dict] = {  # one line per field, for a training command's --help
        "her_lessons": "lessons that get hindsight goals: tasks separated by commas, or all",
        "long_horizon_lessons": "lessons trained with --long-horizon-discount: tasks separated by commas, or none",
        "long_horizon_discount": "discount of the long-horizon lessons",
        "exploration_lessons": "lessons trained toward --exploration-target-entropy-per-action (tasks, or none)",
        "exploration_target_entropy_per_action": "target entropy per action in the exploration lessons",
        "exploration_noise_correlation": "AR(1) correlation per step of the exploration lessons' noise (0: white)",
        "fresh_replay_lessons": "lessons that start with an empty replay: tasks separated by commas, or none",
    }
    LESSON_LIST_FIELDS: ClassVar[tuple] = ("her_lessons", "long_horizon_lessons", "exploration_lessons",
                                           "fresh_replay_lessons")

    def __post_init__(self):
        for name in self.LESSON_LIST_FIELDS:
            lessons = getattr(self, name)
            if isinstance(lessons, str) or not all(isinstance(t, str) and t for t in lessons):
                raise ValueError(f"{name} must be a tuple of task names, e.g. ('lesson1',), got {lessons!r}")
            object.__setattr__(self, name, tuple(lessons))
        if not 0.0 < self.long_horizon_discount <= 1.0:
            raise ValueError(f"long_horizon_discount must be in (0, 1], got {self.long_horizon_discount}")
        if not np.isfinite(self.exploration_target_entropy_per_action):
            raise ValueError("exploration_target_entropy_per_action must be finite, "
                             f"got {self.exploration_target_entropy_per_action}")
        if not 0.0 <= self.exploration_noise_correlation < 1.0:
            raise ValueError("exploration_noise_correlation must be in [0, 1) (0 = white noise), "
                             f"got {self.exploration_noise_correlation}")

    def her_ratio(self, task: str, config: SACConfig) -> float:
        """The hindsight share of the batches while training on ``task``."""
        return config.her_ratio if not self.her_lessons or task in self.her_lessons else 0.0

    def discount(self, task: str, config: SACConfig) -> float:
        return self.long_horizon_discount if task in self.long_horizon_lessons else config.discount

    def target_entropy(self, task: str, config: SACConfig, action_size: int) -> float:
        if task in self.exploration_lessons:
            return self.exploration_target_entropy_per_action * float(action_size)
        return config.resolved_target_entropy(action_size)

    def noise_correlation(self, task: str) -> float:
        """The exploration noise's correlation per control step while training on ``task``."""
        return self.exploration_noise_correlation if task in self.exploration_lessons else 0.0

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        if not d["fresh_replay_lessons"]:  # as runs from before the field have it: their fingerprints hold
            del d["fresh_replay_lessons"]
        return {k: list(v) if k in self.LESSON_LIST_FIELDS else v for k, v in d.items()}

    @classmethod
    def from_dict(cls, d: dict) -> "LessonSettings":
        unknown = set(d) - {f.name for f in dataclasses.fields(cls)}
        if unknown:
            raise ValueError(f"unknown LessonSettings fields: {sorted(unknown)}")
        return cls(**{k: tuple(v) if k in cls.LESSON_LIST_FIELDS else v for k, v in d.items()})


@dataclasses.dataclass(frozen=True)
class Lesson:
    domain: str
    task: str
    steps: int


def parse_plan(text: str, default_domain: Optional[str] = None) -> List[Lesson]:
    """'point_mass/easy:2000,point_mass/hard:5000' -> [Lesson, ...]; a lesson without a domain
    ('easy:2000') is on ``default_domain``."""
    lessons = []
    for item in filter(None, (s.strip() for s in text.split(","))):
        try:
            name, steps = item.rsplit(":", 1)
            steps = int(float(steps))
        except (ValueError, OverflowError):
            raise ValueError(f"bad lesson {item!r}: expected [domain/]task:steps") from None
        domain, task = name.split("/", 1) if "/" in name else (default_domain, name)
        if domain is None:
            raise ValueError(f"lesson {item!r} names no domain: expected domain/task:steps")
        if steps <= 0:
            raise ValueError(f"lesson {item!r} has a non-positive step budget")
        lessons.append(Lesson(domain, task, steps))
    if not lessons:
        raise ValueError("empty lesson plan")
    return lessons


def format_plan(plan: Sequence[Lesson]) -> str:
    return ",".join(f"{l.domain}/{l.task}:{l.steps}" for l in plan)


def run_identity(plan: Sequence[Lesson], config: SACConfig, seed: int, lessons: "LessonSettings" = None,
                 extra: Optional[dict] = None) -> dict:
    """What makes two runs the same run: the part of a checkpoint's fingerprint known before building it
    (a resume is checked against it before anything is touched); ``extra``: what the environments
    add (their options, say), beside the config, the lesson settings, the plan and the seed."""
    return {"config": config.to_dict(), "lessons": (lessons or LessonSettings()).to_dict(),
            "plan": format_plan(plan), "seed": seed, **(extra or {})}


def current_fingerprint(stored: dict) -> dict:
    """A checkpoint's fingerprint as this version writes it for the same run: a field SACConfig no
    longer has is dropped where it holds the value that now goes without saying
    (SACConfig.REMOVED_FIELDS; another value stays, and then no run matches it), and a field added
    since is read as the value that computes what the run computed (SACConfig.ADDED_FIELDS)."""
    config = stored.get("config")
    if not isinstance(config, dict):
        return stored
    removed = SACConfig.REMOVED_FIELDS
    config = {k: v for k, v in config.items() if not (k in removed and v == removed[k])}
    return {**stored, "config": {**SACConfig.ADDED_FIELDS, **config}}


def run_files(run_dir: str) -> Tuple[str, str, str]:
    """A run directory's checkpoint, per-episode metrics and periodic evaluations."""
    return (os.path.join(run_dir, checkpoint.FILE_NAME), os.path.join(run_dir, "metrics.jsonl"),
            os.path.join(run_dir, "evals.jsonl"))


def check_lesson_names(plan, config: SACConfig, lessons: LessonSettings, other_tasks: Sequence[str] = (),
                       goal_tasks: bool = True) -> None:
    """ValueError naming the field if a per-lesson setting names a task that is neither in ``plan``
    nor in ``other_tasks``: a misspelt lesson would silently turn its setting off. ``goal_tasks``:
    whether the plan's tasks have goals (``her_lessons`` is checked only then, as HER applies only there)."""
    named = {"her_lessons": lessons.her_lessons if config.her_ratio > 0 and goal_tasks else (),
             "long_horizon_lessons": lessons.long_horizon_lessons,
             "exploration_lessons": lessons.exploration_lessons,
             "fresh_replay_lessons": lessons.fresh_replay_lessons}
    known = {lesson.task for lesson in plan} | set(other_tasks)
    for field, lessons in named.items():
        unknown = sorted(set(lessons) - known)
        if unknown:
            raise ValueError(f"{field} names {unknown}, not a task of this plan's domains "
                             f"(tasks: {', '.join(sorted(known))})")


class CurriculumRun:
    """A learner, its replay and its position in a lesson plan, with checkpoints.

    Checkpoints hold the learner state (parameters, optimiser states,
    temperature, update counter, RNG key), the actor's key, the replay buffer
    (filled part) and its sampling RNG, the loop counters, the lesson index and
    steps into it, and, given an ``episode_state``, the open episode (simulation
    state, the model fields the task changed, task RNG and per-episode variables,
    e.g. lesson 3's carried-over pose), so a resumed run continues bit-exactly,
    even mid-episode. All of it is data (agents/checkpoint.py), nothing pickled.
    """

    def __init__(self, plan: Sequence[Lesson], config: SACConfig, seed: int, run_dir: str,
                 make_environment: Callable, checkpoint_every: int = 10_000, name: str = "run",
                 lessons: Optional[LessonSettings] = None, residual=None, identity: Optional[dict] = None,
                 episode_probe: Optional[Callable] = None, keep_lesson_checkpoints: bool = False,
                 episode_state=None):
        """``make_environment(lesson, seed)`` builds a lesson's environment; ``lessons``, what
        changes with the lesson (default: nothing); ``residual``, a residual policy's (base policy
        factory, scale) (SACBuilder); ``identity``, what the fingerprint holds beside the config,
        lesson settings, plan and seed (the environments' options); ``episode_probe(env)``, the metrics an
        episode's record gets from its last state (SACBuilder.make_components).
        ``keep_lesson_checkpoints`` also writes a checkpoint at the end of every lesson but the
        last, ``after_lessonK.ckpt`` (K lessons done): the policy of the first K lessons.
        ``episode_state`` stores an environment's open episode as data, for checkpoints: anything with
        ``model_reference(env)`` (taken when a lesson's environment is made), ``capture(env, timestep,
        flat_observation, reference)`` and ``restore(env, state, reference) -> (timestep,
        flat_observation)``, e.g. the domain glue's environment_state module; without one a resumed
        run starts a fresh episode."""
        self.keep_lesson_checkpoints = bool(keep_lesson_checkpoints)
        self.episode_state = episode_state
        self.plan = list(plan)
        self.config, self.seed, self.run_dir, self.name = config, seed, run_dir, name
        self.lessons = lessons or LessonSettings()
        self.identity = dict(identity or {})
        self.checkpoint_every = int(checkpoint_every)
        self.make_environment = make_environment
        self.lesson_index = 0
        self.lesson_steps = 0
        os.makedirs(run_dir, exist_ok=True)
        self.loop = SACBuilder(config).make_components(self._make_lesson_env(0), seed, residual, episode_probe)
        self._enter_lesson()
        self.checkpoint_path, self.metrics_path, self.evals_path = run_files(run_dir)

    # -- lessons ---------------------------------------------------------------------------
    def _make_lesson_env(self, index):
        env = self.make_environment(self.plan[index], self.seed + 1000 * (index + 1))
        # The environment as made: a checkpoint stores what its episodes changed since.
        self._model_reference = None if self.episode_state is None else self.episode_state.model_reference(env)
        return env

    def _enter_lesson(self):
        """What the loop changes with the lesson besides the environment: the hindsight share,
        the discount, the target entropy and the exploration noise's correlation."""
        loop, task, lessons = self.loop, self.lesson.task, self.lessons
        loop.her_ratio = lessons.her_ratio(task, self.config)
        loop.learner.set_discount(lessons.discount(task, self.config))
        loop.learner.set_target_entropy(lessons.target_entropy(task, self.config, loop.learner.networks.action_size))
        loop.actor.noise_correlation = lessons.noise_correlation(task)

    def lesson_checkpoint_path(self, lessons_done: int) -> str:
        """Where ``keep_lesson_checkpoints`` writes the checkpoint after ``lessons_done`` lessons."""
        return os.path.join(self.run_dir, checkpoint.LESSON_FILE_NAME.format(lessons_done=lessons_done))

    @property
    def total_steps(self) -> int:
        return sum(l.steps for l in self.plan)

    @property
    def lesson(self) -> Lesson:
        return self.plan[min(self.lesson_index, len(self.plan) - 1)]

    @property
    def done(self) -> bool:
        return self.lesson_index >= len(self.plan)

    def lesson_boundaries(self) -> List[int]:
        return list(np.cumsum([l.steps for l in self.plan]))

    # -- checkpoints -----------------------------------------------------------------------
    def fingerprint(self) -> dict:
        return {**run_identity(self.plan, self.config, self.seed, self.lessons, self.extra_identity()),
                "observation_layout": self.loop.flattener.describe(),
                "action_size": self.loop.actor.adapter.size}

    def extra_identity(self) -> dict:
        """What the fingerprint holds beside config, plan and seed (``identity``, by default)."""
        return self.identity

    # A stored fingerprint as this version writes it, before a restore compares it with the run's.
    current_fingerprint = staticmethod(current_fingerprint)

    def state_dict(self) -> dict:
        loop = self.loop
        environment = None
        try:
            if self.episode_state is not None:
                environment = self.episode_state.capture(*loop.episode_state(), self._model_reference)
        except checkpoint.NotData as e:  # documented fallback: resume then starts a fresh episode
            print(f"warning: the open episode cannot be stored ({e}); a resume will start a fresh episode")
        return {
            "learner": trees.to_arrays(loop.learner.get_state()),
            "actor_key": np.asarray(loop.actor.key),
            "actor_noise": None if loop.actor.noise is None else np.asarray(loop.actor.noise),
            "actor_rng": loop.actor.rng.bit_generator.state,
            "replay": loop.replay.state_dict(),
            "loop": loop.state_dict(),
            "lesson_index": self.lesson_index,
            "lesson_steps": self.lesson_steps,
            "environment": environment,
            "latest_metrics": loop.metrics_as_floats(),
        }

    def save_checkpoint(self, path: Optional[str] = None):
        checkpoint.save(path or self.checkpoint_path, self.state_dict(), self.fingerprint())

    # What `restore` reads from a checkpoint's payload.
    STATE_FIELDS = ("learner", "actor_key", "actor_noise", "replay", "loop", "lesson_index", "lesson_steps",
                    "environment", "latest_metrics")

    def restore(self, path: Optional[str] = None):
        path = path or self.checkpoint_path
        state = checkpoint.load(path, self.fingerprint(), self.current_fingerprint)
        missing = [k for k in self.STATE_FIELDS if k not in state]
        if missing:
            raise checkpoint.CheckpointError(f"{path} lacks the run state {missing} (not written by a CurriculumRun)")
        loop = self.loop
        try:
            stored = state_layout.upgrade(state["learner"])  # an earlier layout resumes
            loop.learner.set_state(trees.rebuild(stored, loop.learner.state, "the stored learner"))
        except ValueError as e:
            raise checkpoint.CheckpointError(f"{path}: {e}") from None
        loop.actor.update(loop.learner.policy_params)
        loop.actor.key = np.asarray(state["actor_key"])
        if "actor_rng" in state:
            loop.actor.rng.bit_generator.state = state["actor_rng"]
        else:  # checkpoints written before the actor sampled in numpy have its key alone
            loop.actor.rng = loop.actor.rng_from_key(loop.actor.key)
        noise = state["actor_noise"]
        loop.actor.noise = None if noise is None else np.asarray(noise, np.float32)
        loop.replay.load_state_dict(state["replay"])
        self.lesson_index, self.lesson_steps = state["lesson_index"], state["lesson_steps"]
        if state["environment"] is not None and self.episode_state is not None:
            env = self._make_lesson_env(min(self.lesson_index, len(self.plan) - 1))
            try:
                episode = self.episode_state.restore(env, state["environment"], self._model_reference)
            except (ValueError, KeyError, TypeError) as e:
                raise checkpoint.CheckpointError(f"{path}: its open episode does not fit this run's environment "
                                                 f"({type(e).__name__}: {e})") from None
            loop.resume_episode(env, *episode)
        elif not self.done:
            loop.set_environment(self._make_lesson_env(self.lesson_index), close_episode=False)
        self._enter_lesson()
        loop.load_state_dict(state["loop"])
        loop.latest_metrics = state["latest_metrics"]
        for p in (self.metrics_path, self.evals_path):  # drop records written after the checkpoint
            _truncate_jsonl(p, loop.env_steps)

    # -- Algorithm 1 -----------------------------------------------------------------------
    def run(self, progress=None, on_eval: Optional[Callable] = None, eval_at: Sequence[int] = (),
            until_step: Optional[int] = None, chunk: int = 500, stop_requested: Callable[[], bool] = lambda: False):
        """Run the remaining plan, or only until ``until_step`` control steps (then return, the
        run not done: a step budget). `on_eval(run)` is called when env_steps hits a value in eval_at.
        When `stop_requested()` turns true (polled between chunks: a Ctrl-C handler's flag, say) a
        checkpoint is written, then KeyboardInterrupt raised.
        An episode a lesson's end cuts off gets its metrics line too (``"cut": true``)."""
        self._run(progress, on_eval, eval_at, until_step, chunk, stop_requested)

    def _stop_if_interrupted(self, metrics_file, stop_requested):
        if stop_requested():
            metrics_file.flush()
            self.save_checkpoint()
            raise KeyboardInterrupt(f"checkpoint written at step {self.loop.env_steps}: {self.checkpoint_path}")

    def _run(self, progress, on_eval, eval_at, until_step, chunk, stop_requested):
        loop = self.loop
        eval_at = sorted(set(int(s) for s in eval_at))
        metrics_file = open(self.metrics_path, "a")

        def on_episode(record):
            record.update(lesson=self.lesson_index + 1, task=self.lesson.task, run=self.name,
                          updates=loop.learner.num_updates, **loop.metrics_as_floats())
            metrics_file.write(json.dumps(record) + "\n")
            if progress is not None:
                progress.on_episode(record)

        def crossed(before, after, period):
            return after // period > before // period

        try:
            while not self.done:
                self._stop_if_interrupted(metrics_file, stop_requested)
                lesson = self.plan[self.lesson_index]
                n = min(chunk, lesson.steps - self.lesson_steps)
                n = min(n, self.checkpoint_every - loop.env_steps % self.checkpoint_every)
                upcoming = [s for s in eval_at if s > loop.env_steps]
                if upcoming:
                    n = min(n, upcoming[0] - loop.env_steps)
                if until_step is not None:
                    if loop.env_steps >= until_step:
                        return
                    n = min(n, until_step - loop.env_steps)
                before = loop.env_steps
                ran = loop.run(n, on_episode=on_episode)
                self.lesson_steps += ran
                if progress is not None:
                    progress.update(ran, self)
                if self.lesson_steps >= lesson.steps:  # next lesson; everything else carries over
                    cut = loop.cut_episode()
                    if cut is not None:
                        on_episode(cut)
                    self.lesson_index += 1
                    self.lesson_steps = 0
                    if not self.done:
                        loop.set_environment(self._make_lesson_env(self.lesson_index))
                        if self.lesson.task in self.lessons.fresh_replay_lessons:
                            loop.replay.clear()
                        self._enter_lesson()
                        if self.keep_lesson_checkpoints:
                            self.save_checkpoint(self.lesson_checkpoint_path(self.lesson_index))
                if on_eval is not None and any(before < s <= loop.env_steps for s in eval_at):
                    metrics_file.flush()
                    on_eval(self)
                if crossed(before, loop.env_steps, self.checkpoint_every) or self.done:
                    metrics_file.flush()
                    self.save_checkpoint()
            self._stop_if_interrupted(metrics_file, stop_requested)
        finally:
            metrics_file.close()


def read_records(path: str) -> list:
    """The records of a JSON-lines file (metrics.jsonl, evals.jsonl). A torn last line (a crash
    mid-write; no checkpoint can include it) is dropped; any other bad line is a ValueError
    naming the file and line."""
    if not os.path.exists(path):
        return []
    with open(path) as f:
        lines = f.read().split("\n")
    records = []
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            record = json.loads(line)
        except ValueError as error:
            if number == len(lines):  # no newline after it: written in part
                break
            raise ValueError(f"{path}: line {number} is not a JSON record ({error})") from None
        if not isinstance(record, dict):
            raise ValueError(f"{path}: line {number} is not a JSON object")
        records.append(record)
    return records


def _truncate_jsonl(path: str, max_env_steps: int):
    """Keep the records of ``path`` a checkpoint at ``max_env_steps`` includes (and no torn line)."""
    if not os.path.exists(path):
        return
    records = read_records(path)
    kept = [r for r in records if r.get("env_steps", 0) <= max_env_steps]
    with open(path) as f:
        torn = not f.read().endswith("\n")
    if len(kept) != len(records) or torn:
        with open(path, "w") as f:
            f.writelines(json.dumps(r) + "\n" for r in kept)
