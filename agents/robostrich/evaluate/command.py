"""`robostrich-evaluate CHECKPOINT`: re-evaluate a checkpoint as the end of a training run does.

It writes the same reports, figures and Rerun recordings (agents/robostrich/evaluate/evaluation.py:
held-out targets, new targets, `track`, the lookup beside the agent on the arm); with `--web` it then
serves the recordings in the browser until Ctrl-C (robostrich_suite/web_viewer.py). The flags of the
new targets are robostrich-train's too.
"""
import argparse
import os
import sys
from typing import Optional

import numpy as np

from agents.robostrich import figures
from agents.robostrich.run_spec import parse_plan
from agents.robostrich.domains import as_domain
from agents.robostrich.evaluate.evaluation import (MAX_TARGETS, check_heldout_task, check_track_task,
                                                    checked_fingerprint, checkpoint_domain, default_heldout_task,
                                                    episode_count, evaluate_agent, evaluate_lookup,
                                                    load_run_from_checkpoint, summary_lines, target_count)
from agents.robostrich.lookup import LABEL as LOOKUP_LABEL
from agents.sac.builder import SACBuilder
from robostrich_suite import cli as cli_lib
from robostrich_suite import atomic_files, outputs, web_viewer
from robostrich_suite import progress as progress_lib
from robostrich_suite.studies import new_targets as new_targets_lib

MAX_LABEL_BYTES = 100  # a label starts file names (LABEL_heldout_moving.json): well under a name's 255


def evaluation_label(text: str) -> str:
    """argparse type of --label: a name that starts the report files' names, not a path (a label
    with a separator or '..' would write outside --out), nor the lookup baseline's own."""
    if not text or text in (".", "..") or any(c in text for c in ("/", "\\", "\0")):
        raise argparse.ArgumentTypeError(f"must be a name for the report files (no '/', not '..'), got {text!r}")
    if len(os.fsencode(text)) > MAX_LABEL_BYTES:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_LABEL_BYTES} bytes, got {len(os.fsencode(text))}")
    if text == LOOKUP_LABEL:
        raise argparse.ArgumentTypeError(f"{LOOKUP_LABEL!r} names the lookup baseline's reports; choose another")
    return text


def add_new_target_flags(parser) -> None:
    """--new-targets and --new-target-seed, as robostrich-evaluate and robostrich-train take them."""
    parser.add_argument("--new-targets", type=cli_lib.whole_number(0, MAX_TARGETS), default=None,
                        help="new targets on the arm: level poses at least 1 cm from every pose the agent trained "
                             "on, made once per routing and seed, then cached (0: none; default: "
                             f"{new_targets_lib.COUNT}, or as many as the held-out targets asked for where fewer)")
    parser.add_argument("--new-target-seed", type=cli_lib.seed, default=new_targets_lib.SEED,
                        help="seed of the new targets' first draw (default: %(default)s)")


def new_targets_of(domain, args, heldout_count: Optional[int]) -> Optional[np.ndarray]:
    """The new targets the flags ask for on ``domain`` (made now if not cached), None for none; by
    default as many as ``heldout_count`` where that is fewer than the default count (a quick
    evaluation stays quick)."""
    domain = as_domain(domain)
    count = args.new_targets if args.new_targets is not None else min(new_targets_lib.COUNT,
                                                                        heldout_count or new_targets_lib.COUNT)
    if not count or not domain.is_arm:
        return None
    return domain.new_targets(count, args.new_target_seed)


def start_line(args, domain, track_task: Optional[str]) -> str:
    """What the evaluation is about to do, in words: the checkpoint, its domain and what it is judged on."""
    kinds = ["held-out targets"] + (["new targets"] if domain.is_arm and args.new_targets != 0 else []) \
        + ([f"the {track_task} task"] if track_task else [])
    return (f"evaluating {args.checkpoint} on {domain.name}" + (f" ({domain.layout})" if domain.layout else "")
            + f": {', '.join(kinds)}" + (", and the lookup baseline on the same" if domain.is_arm else ""))


def main(argv=None):
    parser = cli_lib.Parser(description="Evaluate a checkpoint (and, on the arm, the lookup baseline): "
                                                 "held-out targets and the track task.")
    parser.add_argument("checkpoint", help="checkpoint.ckpt written by robostrich-train")
    parser.add_argument("--out", default=None, help="report directory (default: next to the checkpoint)")
    parser.add_argument("--label", type=evaluation_label, default="eval",
                        help="name of this evaluation, the start of its report files' names (default: %(default)s)")
    parser.add_argument("--heldout-task", default=None,
                        help="task for held-out targets (default: lesson2 on robostrich, else the last lesson)")
    parser.add_argument("--track-task", default="track",
                        help="task of the tracking evaluation; '' to skip it (default: %(default)s)")
    parser.add_argument("--num-targets", type=target_count, default=None,
                        help=f"held-out targets (default: all; at most {MAX_TARGETS})")
    add_new_target_flags(parser)
    parser.add_argument("--no-rerun", action="store_true", help="no .rrd recordings")
    parser.add_argument("--no-figures", action="store_true", help="no PNG figures")
    parser.add_argument("--no-progress", "--quiet", dest="quiet", action="store_true", help="no progress bar")
    web_viewer.add_flags(parser)
    args = parser.parse_args(argv)
    out = args.out or os.path.join(os.path.dirname(os.path.abspath(args.checkpoint)), "evaluation")
    outputs.check_directory(out)
    web_viewer.check(args)
    fingerprint = checked_fingerprint(args.checkpoint)  # every input checked before the run is rebuilt
    domain = checkpoint_domain(fingerprint)
    track_task = check_track_task(domain, args.track_task)
    if args.web and not track_task:
        raise ValueError("--web serves the track task's recordings, and this evaluation runs no track task")
    heldout_task = check_heldout_task(domain, args.heldout_task
                                      or default_heldout_task(domain, parse_plan(fingerprint["plan"])[-1].task))
    if not args.quiet:  # before the seconds of making new targets and rebuilding the run
        print(start_line(args, domain, track_task), file=sys.stderr, flush=True)
    new = new_targets_of(domain, args, args.num_targets)
    run = load_run_from_checkpoint(args.checkpoint)
    actor = SACBuilder.make_eval_actor(run.loop)
    labels = 2 if domain.is_arm else 1  # the lookup beside the agent on the arm
    total = labels * episode_count(domain, args.num_targets, track_task, 0 if new is None else len(new))
    with progress_lib.bar(not args.quiet, total=total, desc="evaluation", unit="episode", dynamic_ncols=True) as bar:
        on_episode = bar.update if bar is not None else None
        reports = {args.label: evaluate_agent(actor, run.loop.flattener, out, args.label, domain, heldout_task,
                                              track_task or None, args.num_targets,
                                              env_steps=run.loop.env_steps, record=not args.no_rerun,
                                              action_repeat=run.config.action_repeat, on_episode=on_episode,
                                              new_targets=new)}
        lookup = evaluate_lookup(out, domain, heldout_task, track_task or None, args.num_targets,
                                 not args.no_rerun, on_episode=on_episode, new_targets=new)
    if lookup is not None:
        reports["lookup"] = lookup
    if not args.no_figures and "track" in reports[args.label]:
        figures.plot_track({label: r["track"] for label, r in reports.items()},
                           os.path.join(out, f"{args.label}_track.png"))
    summary = {label: {kind: r["summary"] for kind, r in rs.items()} for label, rs in reports.items()}
    atomic_files.write_json(os.path.join(out, "summary.json"), summary)
    print("\n".join(summary_lines(summary)), flush=True)
    print(f"wrote {out}/: summary.json, reports" + ("" if args.no_figures or "track" not in reports[args.label]
                                                    else f", {args.label}_track.png"), flush=True)
    if args.web:
        recordings = [os.path.join(out, f"{label}_track.rrd") for label in reports]
        web_viewer.serve([path for path in recordings if os.path.exists(path)], args.web_port)
    return reports


def cli(argv=None) -> int:
    """Console script `robostrich-evaluate`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-evaluate", argv)


if __name__ == "__main__":
    sys.exit(cli())
