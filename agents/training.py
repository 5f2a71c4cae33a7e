"""The main job: curriculum SAC (lessons 1->3) and a plain-SAC baseline, then evaluation, figures and recordings.

    robostrich-train                               # defaults: writes runs/default, about an hour on 2 CPU cores
    robostrich-train --out runs/default --resume   # continue a killed run from its last checkpoints

Run directory:
    config.json                  the command line and resolved configuration
    curriculum/, baseline/       checkpoint.pkl, metrics.jsonl (one line per episode), evals.jsonl
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
import time
from collections import deque

import numpy as np

from agents import evaluation
from agents.curriculum import (ROBOSTRICH_DOMAINS, CurriculumRun, Lesson, format_plan,
                               parse_plan)
from agents.sac.builder import SACBuilder
from agents.sac.config import SACConfig

DEFAULT_TOTAL_STEPS = 240_000  # per run: 80k control steps per lesson; both runs ~45 min on 2 shared cores
DEFAULT_LESSONS = ("lesson1", "lesson2", "lesson3")


class Progress:
    """tqdm bar over all environment steps of all runs: steps/s, run, lesson, recent return and success."""

    def __init__(self, total: int, enabled: bool = True):
        self.bar = None
        if enabled:
            from tqdm import tqdm
            self.bar = tqdm(total=total, unit="step", dynamic_ncols=True, smoothing=0.05)
        self.returns = deque(maxlen=20)
        self.successes = deque(maxlen=50)

    def on_episode(self, record):
        self.returns.append(record["return"])
        self.successes.append(float(record["success"]))

    def update(self, n, run):
        if self.bar is None:
            return
        self.bar.update(n)
        self.bar.set_postfix(run=run.name, lesson=f"{run.lesson_index + 1 if not run.done else len(run.plan)}"
                             f"/{len(run.plan)}", ret=f"{np.mean(self.returns) if self.returns else float('nan'):.1f}",
                             succ=f"{np.mean(self.successes) if self.successes else float('nan'):.2f}",
                             refresh=False)

    def reset_window(self):
        self.returns.clear()
        self.successes.clear()

    def close(self):
        if self.bar is not None:
            self.bar.close()


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid int value: {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive number of steps, got {value}")
    return value


def build_parser():
    p = argparse.ArgumentParser(description="Train curriculum SAC (and a plain-SAC baseline) on the Robostrich arm.")
    p.add_argument("--out", default="runs/default", help="run directory")
    p.add_argument("--resume", action="store_true", help="continue from the checkpoints in --out")
    p.add_argument("--domain", default="robostrich")
    p.add_argument("--steps", type=int, default=DEFAULT_TOTAL_STEPS,
                   help="total environment steps of the curriculum, split evenly over its lessons")
    p.add_argument("--lessons", default=",".join(DEFAULT_LESSONS), help="lesson tasks, in order")
    p.add_argument("--plan", default=None,
                   help="explicit plan '[domain/]task:steps,...' (overrides --steps/--lessons)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--checkpoint-every", type=positive_int, default=25_000,
                   help="environment steps between checkpoints (default: %(default)s)")
    p.add_argument("--baseline", action=argparse.BooleanOptionalAction, default=True,
                   help="also train plain SAC on the final lesson with the same total budget")
    p.add_argument("--eval-every", type=int, default=None, help="held-out evaluation period (default: steps/6)")
    p.add_argument("--num-eval-targets", type=int, default=20,
                   help="held-out targets in the periodic evaluations (the final one uses all)")
    p.add_argument("--final-eval-targets", type=int, default=None,
                   help="held-out targets in the final evaluation (default: all)")
    p.add_argument("--heldout-task", default=None,
                   help="task for held-out evaluation (default: lesson2 on robostrich, i.e. eq. 10 from the "
                        "fixed initial pose; else the final lesson)")
    p.add_argument("--track-task", default="track")
    p.add_argument("--no-rerun", action="store_true")
    p.add_argument("--no-figures", action="store_true")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--stop-at-step", type=int, default=None, help=argparse.SUPPRESS)  # imitates a kill (tests)
    g = p.add_argument_group("SAC")
    g.add_argument("--batch-size", type=int, default=256)
    g.add_argument("--hidden", type=str, default="256,256")
    g.add_argument("--learning-rate", type=float, default=3e-4)
    g.add_argument("--discount", type=float, default=0.99)
    g.add_argument("--tau", type=float, default=0.005)
    g.add_argument("--init-temperature", type=float, default=1.0)
    g.add_argument("--min-replay", type=int, default=2_000, help="transitions before learning starts")
    g.add_argument("--replay-size", type=int, default=1_000_000)
    g.add_argument("--updates-per-call", type=int, default=8)
    g.add_argument("--env-steps-per-call", type=int, default=8,
                   help="agent steps between learner calls; update-to-data ratio = updates-per-call / this")
    g.add_argument("--action-repeat", type=int, default=5, help="control steps per agent decision")
    g.add_argument("--reward-scale", type=float, default=1.0, help="multiplies rewards in the critic's target")
    g.add_argument("--target-entropy", type=float, default=None, help="temperature target (default: -|A|)")
    g.add_argument("--critic-layer-norm", action=argparse.BooleanOptionalAction, default=False,
                   help="LayerNorm in the critics' hidden layers")
    g.add_argument("--her-ratio", type=float, default=0.0,
                   help="share of each batch relabelled with a goal reached later in the episode (HER)")
    g.add_argument("--relabel-rewards", action=argparse.BooleanOptionalAction, default=False,
                   help="recompute sampled rewards with the current lesson's reward function")
    return p


def config_from_args(args) -> SACConfig:
    return SACConfig(batch_size=args.batch_size, learning_rate=args.learning_rate, discount=args.discount,
                     tau=args.tau, init_temperature=args.init_temperature,
                     hidden_sizes=tuple(int(h) for h in args.hidden.split(",") if h),
                     min_replay_size=args.min_replay, max_replay_size=args.replay_size,
                     updates_per_call=args.updates_per_call, env_steps_per_call=args.env_steps_per_call,
                     action_repeat=args.action_repeat, reward_scale=args.reward_scale,
                     target_entropy=args.target_entropy,
                     critic_layer_norm=args.critic_layer_norm, her_ratio=args.her_ratio,
                     relabel_rewards=args.relabel_rewards)


def plan_from_args(args):
    if args.plan:
        return parse_plan(args.plan, default_domain=args.domain)
    tasks = [t for t in args.lessons.split(",") if t]
    per = args.steps // len(tasks)
    steps = [per] * (len(tasks) - 1) + [args.steps - per * (len(tasks) - 1)]
    return [Lesson(args.domain, t, s) for t, s in zip(tasks, steps)]


def read_jsonl(path):
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [json.loads(l) for l in f if l.strip()]


def main(argv=None):
    args = build_parser().parse_args(argv)
    config = config_from_args(args)
    plan = plan_from_args(args)
    total = sum(l.steps for l in plan)
    final = plan[-1]
    domain = final.domain
    heldout_task = args.heldout_task or evaluation.default_heldout_task(domain, final.task)
    track_task = args.track_task if domain in ROBOSTRICH_DOMAINS else None
    run_plans = {"curriculum": plan}
    if args.baseline:
        run_plans["baseline"] = [Lesson(final.domain, final.task, total)]
    existing = [l for l in run_plans if os.path.exists(os.path.join(args.out, l, "checkpoint.pkl"))]
    if not args.resume and existing:
        raise ValueError(f"{args.out} already holds checkpoints ({', '.join(existing)}); "
                         "pass --resume to continue them or choose another --out")
    if args.resume and not existing:  # a typo in --out must not quietly start the whole job afresh
        looked = ", ".join(os.path.join(l, "checkpoint.pkl") for l in run_plans)
        where = (f"{args.out} holds no checkpoint ({looked})" if os.path.isdir(args.out)
                 else f"{args.out} does not exist")
        raise FileNotFoundError(f"--resume: nothing to resume: {where}; check --out, or leave out --resume "
                                "to start a fresh run")
    if args.resume:  # damaged or another configuration: refuse before building anything or touching a file
        from agents import checkpoint
        for label in existing:
            path = os.path.join(args.out, label, "checkpoint.pkl")
            expected = {"config": config.to_dict(), "plan": format_plan(run_plans[label]), "seed": args.seed}
            stored = checkpoint.read_fingerprint(path)
            checkpoint.check_fingerprint({k: stored.get(k, "<missing>") for k in expected}, expected, path)
    os.makedirs(args.out, exist_ok=True)

    boundaries = list(np.cumsum([l.steps for l in plan]))
    eval_every = args.eval_every or max(1, total // 6)
    eval_at = sorted(set(boundaries) | set(range(eval_every, total + 1, eval_every)))

    runs = {}
    for label, run_plan in run_plans.items():
        run = CurriculumRun(run_plan, config, args.seed, os.path.join(args.out, label),
                            checkpoint_every=args.checkpoint_every, name=label)
        if args.resume and os.path.exists(run.checkpoint_path):
            run.restore()  # raises on damaged/mismatched checkpoints, never restarts silently
        runs[label] = run
    # Every checkpoint is restored: only now change the run directory (a rejected resume leaves it as it was).
    for run in runs.values():
        if not (args.resume and os.path.exists(run.checkpoint_path)):
            for p in (run.metrics_path, run.evals_path):  # a run that died before its first checkpoint
                if os.path.exists(p):
                    os.unlink(p)
    evaluation.write_json(os.path.join(args.out, "config.json"), {
        "argv": sys.argv if argv is None else list(argv), "config": config.to_dict(),
        "plans": {k: format_plan(v) for k, v in run_plans.items()}, "seed": args.seed})

    progress = Progress(sum(r.total_steps for r in runs.values()), enabled=not args.quiet)
    progress.bar and progress.bar.update(sum(r.loop.env_steps for r in runs.values()))
    timings = {}
    try:
        for label, run in runs.items():
            if run.done:
                continue
            progress.reset_window()

            def on_eval(r):
                actor = SACBuilder.make_eval_actor(r.loop)
                report = evaluation.evaluate_heldout(actor, r.loop.flattener, domain, heldout_task,
                                                     args.num_eval_targets, action_repeat=config.action_repeat)
                record = {"env_steps": r.loop.env_steps, "lessons_completed": r.lesson_index, "summary": report["summary"]}
                with open(r.evals_path, "a") as f:
                    f.write(json.dumps(record) + "\n")

            start, start_steps = time.time(), run.loop.env_steps
            run.run(progress=progress, on_eval=on_eval, eval_at=eval_at, stop_at_step=args.stop_at_step)
            timings[label] = {"seconds": time.time() - start, "env_steps": run.loop.env_steps - start_steps,
                              "updates": run.loop.learner.num_updates}
    finally:
        progress.close()

    out_eval = os.path.join(args.out, "evaluation")
    finals = {}
    for label, run in runs.items():
        actor = SACBuilder.make_eval_actor(run.loop)
        finals[label] = evaluation.evaluate_agent(actor, run.loop.flattener, out_eval, label, domain, heldout_task,
                                                  track_task, args.final_eval_targets or
                                                  (None if domain in ROBOSTRICH_DOMAINS else args.num_eval_targets),
                                                  env_steps=run.loop.env_steps, record=not args.no_rerun,
                                                  action_repeat=config.action_repeat)
    lookup = evaluation.evaluate_lookup(out_eval, domain, heldout_task, track_task, args.final_eval_targets,
                                        record=not args.no_rerun)
    if lookup is not None:  # the no-learning bar, beside the agents
        finals["lookup"] = lookup
    metrics = {label: read_jsonl(run.metrics_path) for label, run in runs.items()}
    evals = {label: read_jsonl(run.evals_path) for label, run in runs.items()}
    if not args.no_figures:
        from agents import figures
        os.makedirs(os.path.join(args.out, "figures"), exist_ok=True)
        figures.plot_learning_curves(metrics, evals, os.path.join(args.out, "figures", "learning_curves.png"),
                                     lesson_boundaries=boundaries[:-1],
                                     baselines={"lookup": lookup["heldout"]["summary"]} if lookup else None)
        if track_task:
            figures.plot_track({l: f["track"] for l, f in finals.items()},
                               os.path.join(args.out, "figures", "track.png"))
    if not args.no_rerun:
        from agents import recording
        recording.log_training_curves(os.path.join(args.out, "training.rrd"), metrics, evals)
    summary = {"runs": {label: {k: f[k]["summary"] for k in f} for label, f in finals.items()},
               "env_steps": {label: run.loop.env_steps for label, run in runs.items()},
               "updates": {label: run.loop.learner.num_updates for label, run in runs.items()},
               "timings_this_session": timings}
    evaluation.write_json(os.path.join(args.out, "summary.json"), summary)
    print(json.dumps(summary["runs"], indent=1))
    return summary


def cli(argv=None) -> int:
    """Console script `robostrich-train`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    from robostrich_suite import cli as cli_lib
    return cli_lib.run(main, "robostrich-train", argv)


if __name__ == "__main__":
    sys.exit(cli())
