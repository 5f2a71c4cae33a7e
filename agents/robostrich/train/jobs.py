"""What each of robostrich-train's runs is given and does: the run's description (picklable,
for a worker), its periodic and final evaluations, and the lookup's evaluation as a job of its own."""
import dataclasses
import json
import os
import time
from typing import Optional

import numpy as np

from agents.curriculum import read_records
from agents.robostrich.evaluate import episodes, evaluation
from agents.robostrich.train import transfer
from agents.robostrich.domains import Domain
from agents.robostrich.lookup import LABEL as LOOKUP_LABEL
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import RunSpec
from agents.sac.builder import SACBuilder
from robostrich_suite import cli as cli_lib
from robostrich_suite import atomic_files


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
    new_targets: Optional[np.ndarray] = None  # of the final evaluation, made by the parent (domains.Domain.new_targets)


@dataclasses.dataclass(frozen=True)
class PendingRun:
    """A run not built yet (picklable): its description and where it trains, so that the parent of a
    parallel job passes it to a worker instead of building the run (networks, replay, environment)
    itself, which it would only throw away. ``transfer_from``: a checkpoint a fresh run's learner
    starts from (agents/robostrich/train/transfer.py; its content hash is the spec's ``init_from``)."""

    spec: RunSpec
    run_dir: str
    label: str
    checkpoint_every: int
    keep_lesson_checkpoints: bool = False
    transfer_from: Optional[str] = None

    @property
    def plan(self) -> tuple:
        return self.spec.plan

    @property
    def total_steps(self) -> int:
        return sum(l.steps for l in self.plan)

    def build(self, restore: bool) -> DomainRun:
        """The run; restored from its checkpoint when ``restore`` and one exists (raises on a
        damaged or mismatched checkpoint, never restarts silently)."""
        run = DomainRun(self.spec, self.run_dir, self.checkpoint_every, name=self.label,
                        keep_lesson_checkpoints=self.keep_lesson_checkpoints)
        if restore and os.path.exists(run.checkpoint_path):
            run.restore()
        elif self.transfer_from is not None:
            transfer.initialize(run, self.transfer_from, self.spec.init_from)
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
                                          on_episode=progress.evaluated if progress is not None else None,
                                          new_targets=job.new_targets)


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
            lesson_end = r.loop.env_steps in step_boundaries(r.plan)[:-1]  # evaluated on every held-out target
            count = final_targets(job) if lesson_end else job.num_eval_targets
            report = episodes.evaluate_heldout(actor, r.loop.flattener, job.domain, job.heldout_task,
                                               job.domain.heldout_targets(count), count,
                                               action_repeat=config.action_repeat)
            record = {"env_steps": r.loop.env_steps, "lessons_completed": r.lesson_index, "summary": report["summary"]}
            if lesson_end:
                record["lesson_end"] = True
            with open(r.evals_path, "a") as f:
                f.write(json.dumps(record) + "\n")
            if progress is not None:
                progress.periodic(r.name, record)

        start, start_steps = time.time(), run.loop.env_steps
        with atomic_files.naming(run.run_dir, only_unnamed=True), cli_lib.deferred_interrupts():
            # Ctrl-C: a checkpoint between chunks, then KeyboardInterrupt; a failed write of the
            # run's records (a full disk) names where the run writes
            run.run(progress=progress, on_eval=on_eval, eval_at=job.eval_at, stop_requested=cli_lib.interrupted)
        timing = {"seconds": time.time() - start, "env_steps": run.loop.env_steps - start_steps,
                  "updates": run.loop.learner.num_updates}
    reports = evaluation.evaluate_agent(SACBuilder.make_eval_actor(run.loop), run.loop.flattener, job.out_eval,
                                        run.name, job.domain, job.heldout_task, job.track_task, final_targets(job),
                                        env_steps=run.loop.env_steps, record=job.record,
                                        action_repeat=config.action_repeat,
                                        on_episode=progress.evaluated if progress is not None else None,
                                        new_targets=job.new_targets)
    return {"reports": reports, "env_steps": run.loop.env_steps, "updates": run.loop.learner.num_updates,
            "timing": timing}


def step_boundaries(plan) -> list:
    return list(np.cumsum([l.steps for l in plan]))


def lesson_end_evaluations(records: list, plan) -> dict:
    """``{"heldout_after_lessonK": summary}``: the evaluation on every held-out target at the end of
    each lesson of ``plan`` but the last, from the run's evals.jsonl (the last record of each)."""
    names = {int(end): f"heldout_after_{lesson.task}" for end, lesson in zip(step_boundaries(plan)[:-1], plan)}
    return {names[r["env_steps"]]: r["summary"] for r in records
            if r.get("lesson_end") and r["env_steps"] in names}
