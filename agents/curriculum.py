"""The curriculum (Algorithm 1): one agent goes through a list of lessons.

Parameters, optimiser states, temperature and replay are never reset between
lessons; only the environment is swapped. A plain-SAC baseline is the same
runner with a one-lesson plan.
"""
import dataclasses
import json
import os
import pickle
import zlib
from typing import Callable, List, Optional, Sequence, Tuple

import numpy as np

from agents import checkpoint
from agents.sac.builder import SACBuilder
from agents.sac.config import SACConfig


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


def run_identity(plan: Sequence[Lesson], config: SACConfig, seed: int, extra: Optional[dict] = None) -> dict:
    """What makes two runs the same run: the part of a checkpoint's fingerprint known before building it
    (a resume is checked against it before anything is touched); ``extra``: what the environments
    add (their options, say), in the fingerprint beside the config, the plan and the seed."""
    return {"config": config.to_dict(), "plan": format_plan(plan), "seed": seed, **(extra or {})}


class TrainingInterrupted(RuntimeError):
    """Raised by `stop_at_step` to imitate a killed process in tests."""


def run_files(run_dir: str) -> Tuple[str, str, str]:
    """A run directory's checkpoint, per-episode metrics and periodic evaluations."""
    return (os.path.join(run_dir, "checkpoint.pkl"), os.path.join(run_dir, "metrics.jsonl"),
            os.path.join(run_dir, "evals.jsonl"))


def check_lesson_names(plan, config: SACConfig, other_tasks: Sequence[str] = (), goal_tasks: bool = True) -> None:
    """ValueError naming the field if a per-lesson setting names a task that is neither in ``plan``
    nor in ``other_tasks``: a misspelt lesson would silently turn its setting off. ``goal_tasks``:
    whether the plan's tasks have goals (``her_lessons`` is checked only then, as HER applies only there)."""
    named = {"her_lessons": config.her_lessons if config.her_ratio > 0 and goal_tasks else (),
             "long_horizon_lessons": config.long_horizon_lessons,
             "exploration_lessons": config.exploration_lessons}
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
    steps into it, and the pickled environment (physics, task RNG and any task
    state, e.g. lesson 3's carried-over pose), so a resumed run continues
    bit-exactly, even mid-episode.
    """

    def __init__(self, plan: Sequence[Lesson], config: SACConfig, seed: int, run_dir: str,
                 make_environment: Callable, checkpoint_every: int = 10_000, name: str = "run",
                 base_policy: Optional[Callable] = None, identity: Optional[dict] = None,
                 episode_probe: Optional[Callable] = None, keep_lesson_checkpoints: bool = False):
        """``make_environment(lesson, seed)`` builds a lesson's environment; ``base_policy``, a
        residual policy's base (see SACBuilder); ``identity``, what the fingerprint holds beside the
        config, plan and seed (the environments' options); ``episode_probe(env)``, the metrics an
        episode's record gets from its last state (SACBuilder.make_components).
        ``keep_lesson_checkpoints`` also writes a checkpoint at the end of every lesson but the
        last, ``after_lessonK.pkl`` (K lessons done): the policy of the first K lessons."""
        self.keep_lesson_checkpoints = bool(keep_lesson_checkpoints)
        self.plan = list(plan)
        self.config, self.seed, self.run_dir, self.name = config, seed, run_dir, name
        self.identity = dict(identity or {})
        self.checkpoint_every = int(checkpoint_every)
        self.make_environment = make_environment
        self.lesson_index = 0
        self.lesson_steps = 0
        os.makedirs(run_dir, exist_ok=True)
        self.loop = SACBuilder(config).make_components(self._make_lesson_env(0), seed, base_policy, episode_probe)
        self._enter_lesson()
        self.checkpoint_path, self.metrics_path, self.evals_path = run_files(run_dir)

    # -- lessons ---------------------------------------------------------------------------
    def _make_lesson_env(self, index):
        return self.make_environment(self.plan[index], self.seed + 1000 * (index + 1))

    def _enter_lesson(self):
        """What the loop changes with the lesson besides the environment: the hindsight share,
        the discount, the target entropy and the exploration noise's correlation."""
        loop, task = self.loop, self.lesson.task
        loop.her_ratio = self.config.her_ratio_in_lesson(task)
        loop.learner.set_discount(self.config.discount_in_lesson(task))
        loop.learner.set_target_entropy(self.config.target_entropy_in_lesson(task, loop.learner.networks.action_size))
        loop.actor.noise_correlation = self.config.noise_correlation_in_lesson(task)

    def lesson_checkpoint_path(self, lessons_done: int) -> str:
        """Where ``keep_lesson_checkpoints`` writes the checkpoint after ``lessons_done`` lessons."""
        return os.path.join(self.run_dir, f"after_lesson{lessons_done}.pkl")

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
        return {**run_identity(self.plan, self.config, self.seed, self.extra_identity()),
                "observation_layout": self.loop.flattener.describe(),
                "action_size": self.loop.actor.adapter.size}

    def extra_identity(self) -> dict:
        """What the fingerprint holds beside config, plan and seed (``identity``, by default)."""
        return self.identity

    def state_dict(self) -> dict:
        loop = self.loop
        env_blob = None
        try:
            env_blob = zlib.compress(pickle.dumps(loop.episode_state(), pickle.HIGHEST_PROTOCOL), 1)
        except Exception as e:  # documented fallback: resume then resets the episode
            env_blob = None
            print(f"warning: environment is not picklable ({e}); a resume will start a fresh episode")
        return {
            "learner": loop.learner.get_state(),
            "actor_key": np.asarray(loop.actor.key),
            "actor_noise": None if loop.actor.noise is None else np.asarray(loop.actor.noise),
            "replay": loop.replay.state_dict(),
            "loop": loop.state_dict(),
            "lesson_index": self.lesson_index,
            "lesson_steps": self.lesson_steps,
            "environment": env_blob,
            "latest_metrics": loop.metrics_as_floats(),
        }

    def save_checkpoint(self, path: Optional[str] = None):
        checkpoint.save(path or self.checkpoint_path, self.state_dict(), self.fingerprint())

    # What `restore` reads from a checkpoint's payload.
    STATE_FIELDS = ("learner", "actor_key", "actor_noise", "replay", "loop", "lesson_index", "lesson_steps",
                    "environment", "latest_metrics")

    def restore(self, path: Optional[str] = None):
        path = path or self.checkpoint_path
        state = checkpoint.load(path, self.fingerprint())
        missing = [k for k in self.STATE_FIELDS if k not in state]
        if missing:
            raise checkpoint.CheckpointError(f"{path} lacks the run state {missing} (not written by a CurriculumRun)")
        loop = self.loop
        loop.learner.set_state(state["learner"])
        loop.actor.update(loop.learner.policy_params)
        loop.actor.key = np.asarray(state["actor_key"])
        noise = state["actor_noise"]
        loop.actor.noise = None if noise is None else np.asarray(noise, np.float32)
        loop.replay.load_state_dict(state["replay"])
        self.lesson_index, self.lesson_steps = state["lesson_index"], state["lesson_steps"]
        if state["environment"] is not None:
            loop.resume_episode(*pickle.loads(zlib.decompress(state["environment"])))
        elif not self.done:
            loop.set_environment(self._make_lesson_env(self.lesson_index), close_episode=False)
        self._enter_lesson()
        loop.load_state_dict(state["loop"])
        loop.latest_metrics = state["latest_metrics"]
        for p in (self.metrics_path, self.evals_path):  # drop records written after the checkpoint
            _truncate_jsonl(p, loop.env_steps)

    # -- Algorithm 1 -----------------------------------------------------------------------
    def run(self, progress=None, on_eval: Optional[Callable] = None, eval_at: Sequence[int] = (),
            stop_at_step: Optional[int] = None, chunk: int = 500, stop_requested: Callable[[], bool] = lambda: False):
        """Run the remaining plan. `on_eval(run)` is called when env_steps hits a value in eval_at.
        When `stop_requested()` turns true (polled between chunks: a Ctrl-C handler's flag, say) a
        checkpoint is written, then KeyboardInterrupt raised.
        An episode a lesson's end cuts off gets its metrics line too (``"cut": true``)."""
        self._stop_requested = stop_requested
        self._run(progress, on_eval, eval_at, stop_at_step, chunk)

    def _stop_if_interrupted(self, metrics_file):
        if self._stop_requested():
            metrics_file.flush()
            self.save_checkpoint()
            raise KeyboardInterrupt(f"checkpoint written at step {self.loop.env_steps}: {self.checkpoint_path}")

    def _run(self, progress, on_eval, eval_at, stop_at_step, chunk):
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
                self._stop_if_interrupted(metrics_file)
                lesson = self.plan[self.lesson_index]
                n = min(chunk, lesson.steps - self.lesson_steps)
                n = min(n, self.checkpoint_every - loop.env_steps % self.checkpoint_every)
                upcoming = [s for s in eval_at if s > loop.env_steps]
                if upcoming:
                    n = min(n, upcoming[0] - loop.env_steps)
                if stop_at_step is not None:
                    if loop.env_steps >= stop_at_step:
                        raise TrainingInterrupted(f"stopped at step {loop.env_steps}")
                    n = min(n, stop_at_step - loop.env_steps)
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
                        self._enter_lesson()
                        if self.keep_lesson_checkpoints:
                            self.save_checkpoint(self.lesson_checkpoint_path(self.lesson_index))
                if on_eval is not None and any(before < s <= loop.env_steps for s in eval_at):
                    metrics_file.flush()
                    on_eval(self)
                if crossed(before, loop.env_steps, self.checkpoint_every) or self.done:
                    metrics_file.flush()
                    self.save_checkpoint()
            self._stop_if_interrupted(metrics_file)
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
