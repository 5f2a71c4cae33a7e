"""Peer agents on the arm beside ours, in one command: SBX's SAC, TQC and CrossQ (published
defaults, through robostrich_suite/gym_adapter.py), our curriculum SAC, our plain SAC and the lookup.

    python tools/benchmark_peers.py [--steps 100000] [--seeds 0,1] [--ways final,lessons]
                                    [--agents curriculum,plain,sac,tqc,crossq] [--out runs/peers]
                                    [--ours-args='--fine-input-gain 0']

Every run trains for --steps control steps on the main job's task options and layout: a peer
either on the final lesson alone ('final') or through the main job's lessons and shares
('lessons': the same agent and replay, the next lesson's environment); our curriculum goes
through the lessons, our plain SAC trains the final lesson (robostrich-train at this budget).
All are scored by agents/robostrich/evaluate/episodes.py: held-out success from the fixed start every
--eval-every steps (the curves), then every held-out target from the fixed and from moving
starts and `track`. --workers runs at a time, one core each; a finished run is not re-run, and
--record-only writes the record from the runs finished so far.
Writes OUT/peers.json (a results record's input: tools/results_page.py add), OUT/peers.md and
OUT/learning_curves.png. Needs the peers extra: pip install -e '.[peers]'.

Exit status: 0 done; 1 a run failed; 2 bad input or the extra missing (one line).
"""
import argparse
import os
import shlex
import sys

from agents.robostrich.peers import sbx_agents as peers  # needs no sbx to import
from agents.robostrich.train.checks import json_object
from agents.robostrich.evaluate import evaluation
from agents.robostrich.peers import benchmark as bench
from agents.robostrich.peers import record as peers_record
from robostrich_suite import atomic_files
from robostrich_suite import cli as cli_lib
from robostrich_suite import outputs

PROG = "benchmark_peers"
AGENTS = ("curriculum", "plain", *peers.PEERS)


def _names(allowed):
    def parse(text: str) -> tuple:
        names = tuple(dict.fromkeys(s.strip() for s in text.split(",") if s.strip()))
        unknown = [n for n in names if n not in allowed]
        if unknown or not names:
            raise argparse.ArgumentTypeError(f"expected some of {', '.join(allowed)}, got {text!r}")
        return names
    return parse


def build_parser():
    p = argparse.ArgumentParser(prog=PROG, description=__doc__.splitlines()[0], allow_abbrev=False)
    p.add_argument("--steps", type=cli_lib.whole_number(1, 100_000_000), default=100_000,
                   help="control steps of every run (default: %(default)s)")
    p.add_argument("--seeds", type=_names_int, default=(0, 1), help="comma-separated (default: 0,1)")
    p.add_argument("--agents", type=_names(AGENTS), default=AGENTS,
                   help=f"runs besides the lookup (default: {','.join(AGENTS)})")
    p.add_argument("--ways", type=_names(tuple(peers.WAYS)), default=tuple(peers.WAYS),
                   help="how the peers meet the lessons: final (the final lesson only), lessons (through the "
                        "main job's lessons) (default: both)")
    p.add_argument("--eval-every", type=cli_lib.whole_number(1, 100_000_000), default=None,
                   help="control steps between the curves' held-out evaluations (default: steps/10)")
    p.add_argument("--num-eval-targets", type=evaluation.target_count, default=20,
                   help="held-out targets of the curves' evaluations (the final one uses all; default: %(default)s)")
    p.add_argument("--final-eval-targets", type=evaluation.target_count, default=None,
                   help="held-out targets of the final evaluation (default: all)")
    p.add_argument("--track-task", default="track", help="final tracking task; '' to skip it (default: %(default)s)")
    p.add_argument("--workers", type=cli_lib.whole_number(1, cli_lib.MAX_WORKERS),
                   default=min(2, os.cpu_count() or 1), help="runs at a time, one process each (default: %(default)s)")
    p.add_argument("--out", default="runs/peers", help="output directory (default: %(default)s)")
    p.add_argument("--ours-args", default="",
                   help="robostrich-train flags our two runs take besides the main job's, e.g. "
                        "--ours-args='--fine-input-gain 0' for the main job before fine inputs (default: none)")
    p.add_argument("--task-kwargs", type=json_object, default={},
                   help="JSON object of task options every agent trains with, over the main job's (robostrich-train "
                        "--task-kwargs), e.g. '{\"target_between\": 0}' for the main job's list of targets before "
                        "2026-12-07 (default: none)")
    p.add_argument("--record-only", action="store_true",
                   help="train nothing: write the record from the runs finished in --out so far (the others are "
                        "named as unfinished), e.g. after the command was stopped")
    return p


def _names_int(text: str) -> tuple:
    try:
        seeds = tuple(dict.fromkeys(cli_lib.seed(s.strip()) for s in text.split(",") if s.strip()))
    except argparse.ArgumentTypeError as error:
        raise argparse.ArgumentTypeError(f"--seeds: {error}") from None
    if not seeds:
        raise argparse.ArgumentTypeError(f"--seeds names no seed: {text!r}")
    return seeds


def settings_from(args):
    outputs.check_directory(args.out)
    ours_args = tuple(shlex.split(args.ours_args))
    bench.check_ours_args(ours_args)
    return bench.Settings(steps=args.steps, seeds=args.seeds, agents=args.agents, ways=args.ways, out=args.out,
                          eval_every=args.eval_every or max(1, args.steps // 10),
                          num_eval_targets=args.num_eval_targets, final_eval_targets=args.final_eval_targets,
                          track_task=args.track_task or None, ours_args=ours_args, task_kwargs=args.task_kwargs)


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    peers.require()  # before a minute of building: the one line says which extra
    settings = settings_from(args)
    results = bench.run_all(settings, args.workers, say=lambda line: print(f"{PROG}: {line}", flush=True),
                            train=not args.record_only)
    if not any(results.values()):
        raise ValueError(f"--record-only: {args.out} holds no finished run of these settings")
    command = shlex.join(["python", "tools/benchmark_peers.py", *(sys.argv[1:] if argv is None else argv)])
    data = peers_record.record(settings, results, command)
    atomic_files.write_json(os.path.join(args.out, "peers.json"), data)
    peers_record.plot(data, os.path.join(args.out, "learning_curves.png"))
    import results_peers
    table = "\n".join(results_peers.full(data)) + "\n"
    with open(os.path.join(args.out, "peers.md"), "w") as f:
        f.write(table)
    print(table)
    return 0


def cli(argv=None) -> int:
    """``main`` with the module doc's exit statuses: a missing extra or bad input is one line, status 2."""
    try:
        return main(argv)
    except peers.MissingExtra as error:
        print(f"{PROG}: error: {error}", file=sys.stderr)
        return cli_lib.USER_ERROR
    except (ValueError, OSError) as error:
        print(f"{PROG}: error: {cli_lib.error_message(error)}", file=sys.stderr)
        return cli_lib.USER_ERROR


if __name__ == "__main__":
    sys.exit(cli())
