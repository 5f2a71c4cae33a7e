"""``robostrich-layouts``: the suite's layout comparison (robostrich_suite/studies/layout_compare.py)
with the agent's columns: the lookup baseline's held-out success on each case's own targets and,
with ``--train``, a short curriculum run's."""
from __future__ import annotations

import functools
import pathlib

import numpy as np

import robostrich_suite
from agents.replay import ObservationFlattener
from agents.robostrich.evaluate import episodes, evaluation
from agents.robostrich.lookup import lookup_table, LookupPolicy
from agents.robostrich.train.main_job import FIXED_START_ARM_TASK_KWARGS, MAIN_JOB_SAC
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import RunSpec, parse_plan
from agents.sac.builder import SACBuilder
from robostrich_suite import targets
from robostrich_suite import cli as cli_lib
from robostrich_suite.studies import layout_compare

DEFAULT_TRAIN_STEPS = 4000


def heldout_success(case: layout_compare.Case, heldout: np.ndarray, make_actor, seed: int = 10_000) -> dict:
    """``evaluation``'s held-out summary on the case's arm: one lesson-2 episode from the fixed
    start per target.  ``make_actor(flattener)`` gives the policy."""
    env = robostrich_suite.load("robostrich", evaluation.default_heldout_task("robostrich", "lesson3"),
                                task_kwargs=dict(random=seed, arm_spec=case.spec,
                                                 tendon_layout=case.layout, target_pool=heldout[:1]))
    flattener = ObservationFlattener(env.observation_spec())
    actor = make_actor(flattener)
    rows = []
    for target in heldout:
        env.task.target_pool = np.asarray(target, np.float64)[None]
        rows.append(episodes._episode_summary(episodes.rollout(env, actor, flattener)))
    return episodes.summarize(rows)


def lookup_success(case, target_path: pathlib.Path, options) -> dict:
    """The lookup baseline on the case's own targets (its table keeps no held-out pose)."""
    heldout = targets.heldout_targets(target_path) if _has_targets(target_path) else []
    if not len(heldout):
        return {"lookup_success": None}
    table = lookup_table(targets.level_head_poses(target_path), heldout)
    return {"lookup_success": heldout_success(case, heldout, lambda f: LookupPolicy(f, table))["success_rate"]}


def curriculum_success(case, target_path: pathlib.Path, options, steps: int = DEFAULT_TRAIN_STEPS) -> dict:
    """A short curriculum (lessons 1-3 in equal parts, ``robostrich-train``'s learner and
    defaults) on the case's own training targets, then its held-out success."""
    if not _has_targets(target_path) or not len(targets.heldout_targets(target_path)) \
            or not len(targets.training_targets(target_path)):
        return {"curriculum_success": None}
    arm_kwargs = dict(arm_spec=case.spec, tendon_layout=case.layout,
                      target_pool=targets.training_targets(target_path))

    def env_factory(domain, task, env_seed, **task_kwargs):  # the arm stays out of the fingerprint
        return domain.make_environment(task, env_seed, **arm_kwargs, **task_kwargs)

    per_lesson = max(steps // 3, 1)
    plan = parse_plan(",".join(f"lesson{i}:{per_lesson}" for i in (1, 2, 3)))
    run = DomainRun(RunSpec(plan, MAIN_JOB_SAC, options.seed, task_kwargs=FIXED_START_ARM_TASK_KWARGS),
                    str(options.out / "train" / case.label), checkpoint_every=10 ** 9, env_factory=env_factory,
                    name=case.label)
    run.run()
    actor = SACBuilder.make_eval_actor(run.loop)
    summary = heldout_success(case, targets.heldout_targets(target_path), lambda flattener: actor)
    return {"curriculum_success": summary["success_rate"]}


def _has_targets(target_path: pathlib.Path) -> bool:
    return len(targets.level_head_poses(target_path)["head_position"]) > 0


def build_parser() -> cli_lib.Parser:
    parser = layout_compare.build_parser()
    group = parser.add_argument_group("the agent's columns")
    group.add_argument("--no-lookup", action="store_true", help="skip the lookup baseline")
    group.add_argument("--train", action="store_true",
                       help="also train a short curriculum per case on its own targets and "
                            "report its held-out success")
    group.add_argument("--train-steps", type=cli_lib.whole_number(1), default=DEFAULT_TRAIN_STEPS,
                       help="control steps of that run, split over lessons 1-3 (default: %(default)s)")
    return parser


def measures(args) -> tuple:
    """The further measures the options ask for, in the table's order (picklable for the workers)."""
    chosen = () if args.no_lookup else (lookup_success,)
    if args.train:
        chosen += (functools.partial(curriculum_success, steps=args.train_steps),)
    return chosen


def main(argv=None) -> dict:
    return layout_compare.main(argv, build_parser(), measures)


def cli(argv=None) -> int:
    """Console script `robostrich-layouts`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, layout_compare.PROG, argv)
