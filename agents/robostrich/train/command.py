"""The main job: curriculum SAC (lessons 1->3) and a plain-SAC baseline, then evaluation, figures and recordings.

    robostrich-train                               # defaults: writes runs/default (its time: docs/results.md)
    robostrich-train --out runs/default --resume   # continue a killed run from its last checkpoints

Run directory:
    config.json                  the command line and resolved configuration
    curriculum/, baseline/       checkpoint.ckpt, metrics.jsonl (one line per episode), evals.jsonl
    evaluation/                  <label>_heldout.json, <label>_heldout_moving.json, <label>_track.json,
                                 <label>_track.rrd; labels curriculum, baseline and (on the arm) lookup
    figures/                     learning_curves.png, track.png
    training.rrd                 training curves of both runs
    summary.json
"""
import argparse
import json
import os
import sys

from agents import config_flags
from agents.curriculum import format_plan, run_files
from agents.robostrich import figures, recording
from agents.robostrich.evaluate import command as evaluate_command
from agents.robostrich.evaluate import evaluation
from agents.robostrich.lookup import LABEL as LOOKUP_LABEL
from agents.robostrich.train.main_job import (DEFAULT_ARM_LAYOUT, DEFAULT_ARM_TASK_KWARGS, DEFAULT_TOTAL_STEPS,
                                              FRAME_TASK_KWARGS, MAIN_JOB_BY_DOMAIN, MAIN_JOB_LESSON_SHARES,
                                              MAIN_JOB_SAC, MAIN_JOB_STEPS, QUADRUPED_TASK_KWARGS, positive_int)
from agents.robostrich.train.run_directory import check_run_directory, finished_summary, lock_run_directory, previous_init_path
from agents.robostrich.run_spec import DEFAULT_LESSONS
from agents.robostrich.train.checks import TrainingSetup, json_object, prepare, randomize_scales
from agents.robostrich.train.jobs import LookupSpec, PendingRun, RunJob, step_boundaries, final_targets, \
    lesson_end_evaluations, read_jsonl, train_and_evaluate
from agents.robostrich.train.progress import Progress
from agents.robostrich.train.workers import train_in_parallel
from robostrich_suite import cli as cli_lib
from robostrich_suite import atomic_files, outputs


def _add_run_arguments(run) -> None:
    """robostrich-train's flags for what to train: domain, plan, seed, layout, start, workers."""
    run.add_argument("--domain", default="robostrich",
                     help="robostrich (the arm on its frame), robostrich_a1 (on the quadruped) or a dm_control "
                          "domain (default: %(default)s)")
    run.add_argument("--steps", type=positive_int, default=None,
                     help="total control steps of the curriculum (default "
                          + "; ".join(f"{MAIN_JOB_STEPS[d]} on {d}, split "
                                      f"{':'.join(map(str, MAIN_JOB_LESSON_SHARES[d]))} "
                                      "over its lessons" for d in MAIN_JOB_STEPS)
                          + f"; {DEFAULT_TOTAL_STEPS} elsewhere, split evenly)")
    run.add_argument("--lessons", default=None,
                     help="lesson tasks, in order (default: the domain's curriculum: lesson1-3 on robostrich, "
                          "lesson1-4 on robostrich_a1)")
    run.add_argument("--plan", default=None,
                     help="explicit plan '[domain/]task:steps,...' (overrides --steps/--lessons)")
    run.add_argument("--seed", type=cli_lib.seed, default=0,
                     help="random seed of networks, exploration and episodes (default: %(default)s)")
    run.add_argument("--layout", default=None,
                     help="built-in tendon layout of the arm; its own shipped level poses give the training and "
                          f"held-out targets and the lookup table (default on the arm domains: {DEFAULT_ARM_LAYOUT}, "
                          "the reconstruction of the paper's routing; antagonist_pairs: the best routing of our own)")
    run.add_argument("--init-from", default=None, metavar="CHECKPOINT",
                     help="start the curriculum's learner (policy, critics, target critics, optimiser states, "
                          "temperature) from a checkpoint.ckpt of robostrich-train on the same domain or, for "
                          "--domain robostrich_a1, on robostrich (the arm on its frame): its networks are mapped "
                          "onto the a1's observations (agents/robostrich/train/transfer.py). Same tendon layout and networks "
                          "(--hidden-sizes) required; the replay is not carried (other observations); the plain-SAC "
                          "baseline still starts from scratch, so the comparison shows what the transfer brings. "
                          "A --resume may leave it out (the checkpoint holds the transferred state)")
    run.add_argument("--task-kwargs", type=json_object, default={},
                     help="JSON object passed to every training lesson's task, e.g. eq. 10's weights: "
                          "'{\"weights\": {\"position_error\": 10}}' (evaluation keeps the task's defaults). On the "
                          f"arm domains it goes over {json.dumps(DEFAULT_ARM_TASK_KWARGS)}, on robostrich also "
                          f"{json.dumps(FRAME_TASK_KWARGS)}, on robostrich_a1 {json.dumps(QUADRUPED_TASK_KWARGS)} "
                          "(weights merged key by key; "
                          "'{\"weights\": {\"position_precision\": 0, \"attitude_precision\": 0}, "
                          "\"target_sampling\": \"uniform\", "
                          "\"fixed_stored_starts\": 0, \"target_between\": 0}' gives the paper's eq. 10, its "
                          "uniform draw of the stored targets and its fixed starts in lessons 1-2)")
    run.add_argument("--randomize", type=randomize_scales, default=None, metavar="FAMILY=S,...",
                     help="train across robots that differ from the model: each episode draws each family's "
                          "scale from [0, S] (families and scales as robostrich-robustness measures them, "
                          "robostrich_suite/tasks/perturbations.py; all=S for every family); with latency the "
                          "policy also observes its last 3 sent actions, which evaluation and its policy file "
                          "carry (default: the nominal robot)")
    run.add_argument("--baseline", action=argparse.BooleanOptionalAction, default=True,
                     help="also train plain SAC on the final lesson with the same total budget (default: "
                          "--baseline)")
    run.add_argument("--workers", type=cli_lib.whole_number(1, cli_lib.MAX_WORKERS),
                     default=min(2, os.cpu_count() or 1),
                     help="runs trained at once, one process each (default: %(default)s; the curriculum and "
                          "the plain-SAC baseline are independent)")


def _add_file_arguments(files) -> None:
    """robostrich-train's flags for the run directory and its checkpoints."""
    files.add_argument("--out", default="runs/default", help="run directory (default: %(default)s)")
    files.add_argument("--resume", action="store_true", help="continue from the checkpoints in --out")
    files.add_argument("--keep-lesson-checkpoints", action="store_true",
                       help="also keep a checkpoint after every lesson but the last (RUN/after_lessonK.ckpt), "
                            "e.g. the lesson-3 policy to compare lesson 4 with (robostrich-stabilize --reference)")
    files.add_argument("--checkpoint-every", type=positive_int, default=25_000,
                       help="control steps between checkpoints (default: %(default)s)")


def _add_report_arguments(report) -> None:
    """robostrich-train's flags for the evaluations and what is written."""
    report.add_argument("--eval-every", type=positive_int, default=None,
                        help="control steps between held-out evaluations (default: steps/6)")
    report.add_argument("--num-eval-targets", type=evaluation.target_count, default=20,
                        help="held-out targets in the periodic evaluations (the final one uses all; "
                             "default: %(default)s)")
    report.add_argument("--final-eval-targets", type=evaluation.target_count, default=None,
                        help="held-out targets in the final evaluation (default: all)")
    evaluate_command.add_new_target_flags(report)
    report.add_argument("--heldout-task", default=None,
                        help="task for held-out evaluation (default: lesson2 on robostrich, i.e. eq. 10 from the "
                             "fixed initial pose; else the final lesson)")
    report.add_argument("--track-task", default="track",
                        help="task of the final tracking evaluation; '' to skip it (default: %(default)s)")
    report.add_argument("--no-rerun", action="store_true", help="no .rrd recordings of the final evaluation")
    report.add_argument("--no-figures", action="store_true", help="no PNG figures")
    report.add_argument("--no-progress", "--quiet", dest="quiet", action="store_true", help="no progress bar")


def build_parser():
    p = cli_lib.Parser(description="Train curriculum SAC (and a plain-SAC baseline) on the Robostrich arm.")
    _add_run_arguments(p.add_argument_group("what to train"))
    _add_file_arguments(p.add_argument_group("run directory and checkpoints"))
    _add_report_arguments(p.add_argument_group("evaluation and outputs"))
    add_agent_arguments(p)
    return p


def add_agent_arguments(p) -> None:
    """The agent's settings (SACConfig), what changes per lesson (LessonSettings), the residual and --paper-sac."""
    config_flags.add_config_arguments(p.add_argument_group("SAC (agents/sac/config.py; defaults: the main job's, "
                                                           "agents/robostrich/train/main_job.py MAIN_JOB_SAC)"),
                                      MAIN_JOB_SAC, MAIN_JOB_BY_DOMAIN)
    lessons = p.add_argument_group("per lesson (agents/curriculum.py LessonSettings; defaults: "
                                   "agents/robostrich/domain_run.py DEFAULT_LESSONS)")
    config_flags.add_config_arguments(lessons, DEFAULT_LESSONS, MAIN_JOB_BY_DOMAIN)
    lessons.add_argument("--residual-scale", type=float, default=0.0,
                         help="train a residual on the lookup's stored inputs, within this fraction of each "
                              "tendon's half-range (0, the default: the policy gives the whole input)")
    p.add_argument("--paper-sac", action="store_true",
                   help="the paper's plain SAC (Acme defaults, no agent improvements, nothing per lesson); "
                        "flags given explicitly still apply on top")


def main(argv=None):
    """The main job: parse and check everything, train every run, evaluate, report; returns the summary."""
    args = build_parser().parse_args(argv)
    outputs.check_directory(args.out)  # before a minute of building, not after an hour of training
    setup = prepare(args, argv)
    init = check_run_directory(args, setup)
    if not args.quiet:  # before seconds of building and compiling, what they are for
        print("\n".join(start_lines(args, setup)), file=sys.stderr, flush=True)
    with lock_run_directory(args.out):  # released, and its file removed, however this ends
        finished = finished_summary(args, setup)
        if finished is not None:  # a --resume of a finished run: its results, not a second evaluation
            print(f"{args.out} is finished; nothing to resume")
            print_summary(args.out, finished)
            return finished
        specs, runs = start_runs(args, argv, setup, init)
        outcomes, lookup = train_all(args, setup, specs, runs)
        return report(args, setup, specs, outcomes, lookup)


def start_lines(args, setup: TrainingSetup) -> list:
    """What the command is about to do, in words (on stderr with the progress bar): each run's
    lessons and control steps, how a shorter budget compares with the main job's, and the bar's terms."""
    runs = " and ".join(f"{label} ({', '.join(f'{l.task} {l.steps:,}' for l in plan)} control steps)"
                        for label, plan in setup.run_plans.items())
    where = setup.domain.name + (f" ({setup.domain.layout})" if setup.domain.layout else "")
    lines = [f"{'resuming' if args.resume else 'training'} {runs} on {where}, seed {args.seed}, into {args.out}/"]
    main_steps = MAIN_JOB_STEPS.get(setup.domain.name)
    steps = max(sum(l.steps for l in plan) for plan in setup.run_plans.values())
    if main_steps and steps < main_steps:
        lines.append(f"{steps:,} control steps per run are {100 * steps / main_steps:.2g} % of the main job's "
                     f"{main_steps:,}: expect a weaker policy than docs/results.md reports")
    lines.append("progress: return is the mean return of the last 20 training episodes, reached the share of the "
                 "last 50 that reached their target; each held-out evaluation prints a line as it ends")
    return lines


def start_runs(args, argv, setup: TrainingSetup, init: dict):
    """The runs' specs (and, trained here, the runs themselves, restored on --resume); a run that
    died before its first checkpoint loses its records; config.json. Returns (specs, runs)."""
    transferred = {"curriculum": init} if init else {}  # the baseline starts from scratch
    specs = {label: PendingRun(setup.run_spec(args, label, transferred.get(label, {}).get("init_digest")),
                               os.path.join(args.out, label), label, args.checkpoint_every,
                               args.keep_lesson_checkpoints, transfer_from=transferred.get(label, {}).get("init_from"))
             for label in setup.run_plans}
    # Sequential: build (and restore) every run here; parallel: the workers do, once each.
    runs = {} if _parallel(args, specs) else {label: spec.build(restore=args.resume) for label, spec in specs.items()}
    # Every checkpoint is checked: only now change the run directory (a rejected resume leaves it as it was).
    for spec in specs.values():
        checkpoint_path, metrics_path, evals_path = run_files(spec.run_dir)
        if not (args.resume and os.path.exists(checkpoint_path)):
            for p in (metrics_path, evals_path):
                if os.path.exists(p):
                    os.unlink(p)
    atomic_files.write_json(os.path.join(args.out, "config.json"), {
        "argv": sys.argv if argv is None else list(argv), "config": setup.config.to_dict(),
        "lessons": setup.lessons.to_dict(), "residual_scale": setup.residual_scale,
        "task_kwargs": args.task_kwargs, "layout": args.layout,
        "init_from": {"path": init.get("init_from", previous_init_path(args.out)), "sha256": init["init_digest"]}
        if init else None,
        "plans": {k: format_plan(v) for k, v in setup.run_plans.items()}, "seed": args.seed})
    return specs, runs


def _parallel(args, specs) -> bool:
    return args.workers > 1 and len(specs) > 1


def train_all(args, setup: TrainingSetup, specs: dict, runs: dict):
    """Train and evaluate every run, here or one per worker, and the lookup; (outcomes, lookup reports)."""
    total = sum(l.steps for l in setup.plan)
    eval_every = args.eval_every or max(1, total // 6)
    eval_at = sorted(set(step_boundaries(setup.plan)) | set(range(eval_every, total + 1, eval_every)))
    job = RunJob(domain=setup.domain, heldout_task=setup.heldout_task, track_task=setup.track_task,
                 eval_at=tuple(eval_at), num_eval_targets=args.num_eval_targets,
                 final_eval_targets=args.final_eval_targets, out_eval=os.path.join(args.out, "evaluation"),
                 record=not args.no_rerun, new_targets=evaluate_command.new_targets_of(setup.domain, args, args.final_eval_targets))
    episodes = evaluation.episode_count(setup.domain, final_targets(job), setup.track_task,
                                        0 if job.new_targets is None else len(job.new_targets))
    progress = Progress(sum(spec.total_steps for spec in specs.values()), enabled=not args.quiet,
                        evaluations=episodes * (len(specs) + setup.domain.is_arm))  # the lookup's too
    progress.skip(sum(r.loop.env_steps for r in runs.values()))
    stopped = True
    try:
        if _parallel(args, specs):  # the lookup's evaluation joins the workers' queue (a run's core once it is done)
            jobs = {**specs, LOOKUP_LABEL: LookupSpec()} if setup.domain.is_arm else specs
            outcomes = train_in_parallel(jobs, job, progress, args.workers)
            lookup = outcomes.pop(LOOKUP_LABEL)["reports"] if setup.domain.is_arm else None
        else:
            outcomes = {label: train_and_evaluate(run, job, progress) for label, run in runs.items()}
            lookup = LookupSpec().evaluate(job, progress)
        stopped = False
    finally:
        progress.close(cleared=stopped)
    return outcomes, lookup


def report(args, setup: TrainingSetup, specs: dict, outcomes: dict, lookup) -> dict:
    """Figures, the training curves' recording and summary.json (printed); returns the summary."""
    finals = {label: o["reports"] for label, o in outcomes.items()}
    if lookup is not None:  # the no-learning bar, beside the agents
        finals["lookup"] = lookup
    # written by whoever trained, here or in a worker
    metrics = {label: read_jsonl(run_files(spec.run_dir)[1]) for label, spec in specs.items()}
    evals = {label: read_jsonl(run_files(spec.run_dir)[2]) for label, spec in specs.items()}
    if not args.no_figures:
        os.makedirs(os.path.join(args.out, "figures"), exist_ok=True)
        figures.plot_learning_curves(metrics, evals, os.path.join(args.out, "figures", "learning_curves.png"),
                                     lesson_boundaries=step_boundaries(setup.plan)[:-1],
                                     baselines={"lookup": lookup["heldout"]["summary"]} if lookup else None)
        if setup.track_task:
            figures.plot_track({l: f["track"] for l, f in finals.items()},
                               os.path.join(args.out, "figures", "track.png"))
    if not args.no_rerun:
        recording.log_training_curves(os.path.join(args.out, "training.rrd"), metrics, evals)
    summary = {"runs": {label: {k: f[k]["summary"] for k in f} for label, f in finals.items()},
               "lesson_ends": {label: lesson_end_evaluations(evals[label], spec.plan) for label, spec in specs.items()},
               "env_steps": {label: o["env_steps"] for label, o in outcomes.items()},
               "updates": {label: o["updates"] for label, o in outcomes.items()},
               "timings": {label: o["timing"] for label, o in outcomes.items() if o["timing"]}}
    atomic_files.write_json(os.path.join(args.out, "summary.json"), summary)
    print_summary(args.out, summary)
    return summary


def print_summary(out: str, summary: dict) -> None:
    """The run's results in a few lines (evaluation.summary_lines; the JSON is in summary.json) and where they are."""
    print("\n".join(evaluation.summary_lines(summary["runs"])))
    print(f"wrote {out}/: summary.json, evaluation/, checkpoints and records per run"
          + (", figures/" if os.path.isdir(os.path.join(out, "figures")) else "")
          + (", training.rrd" if os.path.exists(os.path.join(out, "training.rrd")) else ""))


def cli(argv=None) -> int:
    """Console script `robostrich-train`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-train", argv)


if __name__ == "__main__":
    sys.exit(cli())
