"""Run a grid of main jobs (seeds x layouts x robostrich-train settings) as Ray tasks, resumably, into one table.

    robostrich-sweep --seeds 0,1,2 --layouts ventral_slips,antagonist_pairs --steps 60000
    robostrich-sweep --grid grid.toml --out runs/grid          # run again to finish what is missing
    robostrich-sweep --grid grid.toml --address ray://head:10001

Each run is robostrich-train itself (its training, checkpoints, evaluation and summary.json) in
SWEEP/runs/GROUP/seed_K, one core each; a group is one layout with one setting. A run whose
summary.json exists is not run again, one with checkpoints is resumed (--resume); a run that fails
is reported and the others go on. SWEEP/sweep.json and sweep.md hold mean [min, max] over seeds per
group (agents/robostrich/sweep/table.py); tools/results_page.py add takes sweep.json.
"""
import argparse
import json
import os
import sys

from agents.robostrich import directory_lock
from agents.robostrich.sweep import grid as sweep_grid
from agents.robostrich.sweep import ray_tasks as sweep_ray
from agents.robostrich.sweep import table as sweep_table
from agents.robostrich.train import command as training
from agents.robostrich.train import checks as training_input  # robostrich-train's own parser and checks, for every group's flags
from robostrich_suite import cli as cli_lib
from robostrich_suite import outputs, parsing
from robostrich_suite.atomic_files import write_text
from robostrich_suite.model import layouts as model_layouts

PROG = "robostrich-sweep"
FORMAT = 1
DEFAULT_SEEDS = [0, 1, 2]


def _comma_list(kind):
    def parse(text: str) -> list:
        items = [item.strip() for item in text.split(",") if item.strip()]
        if not items:
            raise argparse.ArgumentTypeError(f"no item in {text!r}")
        return [kind(item) for item in items]
    parse.__name__ = "comma-separated"
    return parse


def build_parser():
    p = cli_lib.Parser(prog=PROG, allow_abbrev=False, description=__doc__.splitlines()[0],
                       epilog="Any other argument goes to every run's robostrich-train (robostrich-train --help), "
                              "after the grid file's. --seed, --out, --resume and --workers are set for each run.")
    p.add_argument("--grid", metavar="FILE", default=None,
                   help="TOML grid file: seeds, layouts, [train] flags of every run, [settings.NAME] flags of "
                        "each group (agents/robostrich/sweep/grid.py)")
    p.add_argument("--seeds", type=_comma_list(cli_lib.seed), default=None,
                   help="comma-separated seeds, over the grid file's (default: the grid file's, else 0,1,2)")
    p.add_argument("--layouts", type=_comma_list(str), default=None,
                   help="comma-separated tendon layouts, one group each, over the grid file's (default: the grid "
                        "file's, else the domain's own layout)")
    p.add_argument("--out", default="runs/sweep", help="sweep directory; run K of group G trains into "
                                                       "OUT/runs/G/seed_K (default: %(default)s)")
    p.add_argument("--address", default=None,
                   help="an existing Ray cluster (host:port or ray://host:port) whose nodes have robostrich-train "
                        "installed and see --out at the same path (default: a local Ray, started and stopped here)")
    p.add_argument("--num-cpus", type=cli_lib.whole_number(1, cli_lib.MAX_WORKERS), default=None,
                   help="CPUs of the local Ray, one run each (default: every core)")
    p.add_argument("--no-progress", "--quiet", dest="quiet", action="store_true", help="no progress bar")
    return p


def plan(args, passthrough):
    """(groups, runs) of the command line and the grid file, every group's flags checked by
    robostrich-train's own parser (a typo stops the sweep before any run starts)."""
    grid = sweep_grid.read_grid_file(args.grid) if args.grid else {}
    seeds = sweep_grid.check_seeds(args.seeds or grid.get("seeds", DEFAULT_SEEDS), cli_lib.MAX_SEED)
    layouts = args.layouts or grid.get("layouts")
    for layout in layouts or ():  # a misspelt layout stops the sweep, not each of its runs
        model_layouts.check_built_in(layout)
    settings = {name: sweep_grid.flags_of(table, f"settings.{name}") for name, table in grid.get("settings", {}).items()}
    common = sweep_grid.flags_of(grid.get("train", {}), "train") + list(passthrough)
    groups, runs = sweep_grid.build_grid(seeds, layouts, settings, common, args.out)
    for group in groups:
        check_training_flags(group)
    return groups, runs


def check_training_flags(group) -> None:
    """robostrich-train's own checks of the group's flags (its parser, then every value, lesson and
    task option, as it checks them before it trains): a ValueError naming the group, before any run
    of the sweep starts, instead of each run failing in turn."""
    parser = training.build_parser()

    def refuse(message):
        raise ValueError(f"group {group.name}: robostrich-train: {' '.join(message.split())}")
    parser.error = refuse
    argv = list(group.arguments)
    args = parser.parse_args(argv)
    try:
        training_input.prepare(args, argv)
    except (ValueError, TypeError) as error:
        refuse(str(error))


def check_recorded_groups(out: str, groups) -> None:
    """A group keeps the flags it started with (OUT/grid.json): a finished run of other settings
    would otherwise be counted as this one's. Groups may be added."""
    path = os.path.join(out, "grid.json")
    recorded = sweep_grid.read_recorded_groups(path)
    for group in groups:
        if group.name in recorded and recorded[group.name] != list(group.arguments):
            raise ValueError(f"group {group.name} ran with {' '.join(recorded[group.name]) or 'no flags'} in {out}, "
                             f"not {' '.join(group.arguments) or 'no flags'}; choose another --out")
    recorded.update({group.name: list(group.arguments) for group in groups})
    write_text(path, json.dumps(recorded, indent=1) + "\n")


def _outcome(ray, ref) -> dict:
    """A finished task's result; a task that Ray itself could not run (a dead worker, a cancel) as a failure."""
    try:
        return ray.get(ref)
    except ray.exceptions.TaskCancelledError:
        return {"status": "interrupted", "minutes": None, "error": "cancelled before it started"}
    except ray.exceptions.RayError as error:
        lines = [line for line in str(error).splitlines() if line.strip()]
        return {"status": "failed", "minutes": None, "error": f"{type(error).__name__}: {(lines or [''])[-1]}"}


def run_all(ray, pending, total: int, finished: int, quiet: bool, on_end) -> dict:
    """Every pending run as a Ray task of one CPU; ``on_end(outcomes)`` after each ends; a bar over
    all runs. Ctrl-C cancels them (each running one writes its checkpoints first), then raises."""
    from tqdm import tqdm
    task = ray.remote(num_cpus=1, max_retries=0)(sweep_ray.train_run)
    refs = {task.remote(run.argv(), run.run_dir): run for run in pending}
    outcomes = {}
    bar = tqdm(total=total, initial=finished, unit="run", dynamic_ncols=True, disable=quiet, file=sys.stderr)
    try:
        while refs:
            ready, _ = ray.wait(list(refs), num_returns=1, timeout=1.0)
            for ref in ready:
                run = refs.pop(ref)
                outcomes[run] = _outcome(ray, ref)
                bar.update(1)
                bar.set_postfix(failed=sum(o["status"] != "done" for o in outcomes.values()), refresh=False)
                on_end(outcomes)
    except KeyboardInterrupt:
        _stop(ray, refs, outcomes, on_end)
        raise
    finally:
        bar.close()
    return outcomes


def _stop(ray, refs: dict, outcomes: dict, on_end) -> None:
    """Cancel every task and wait while the running ones write their checkpoints."""
    for ref in refs:
        ray.cancel(ref)
    with cli_lib.deferred_interrupts():  # a second Ctrl-C waits too: the checkpoints are being written
        ready, _ = ray.wait(list(refs), num_returns=len(refs), timeout=sweep_ray.INTERRUPT_GRACE_S)
    outcomes.update({refs[ref]: _outcome(ray, ref) for ref in ready})
    on_end(outcomes)


def collect(out: str, groups, runs, outcomes: dict, command) -> dict:
    """sweep.json: every run's state, and per group the aggregate of its finished runs' summaries."""
    entries, by_group = [], {}
    for run in runs:
        outcome = outcomes.get(run) or {}
        status = "done" if run.finished() else outcome.get("status", "not run")
        entries.append({"group": run.group, "seed": run.seed, "run_dir": os.path.relpath(run.run_dir, out),
                        "status": status, "error": outcome.get("error") if status != "done" else None})
        if status == "done":
            by_group.setdefault(run.group, []).append((run, parsing.read_json(run.summary_path)))
    result = {"format": FORMAT, "command": command, "total": len(runs),
              "finished": sum(e["status"] == "done" for e in entries),
              "failed": [e for e in entries if e["status"] == "failed"], "runs": entries, "groups": {}}
    for group in groups:
        done = by_group.get(group.name, [])
        summaries = [summary for _, summary in done]
        agg = sweep_table.aggregate(summaries, [r.seed for r, _ in done],
                                    [sweep_table.run_minutes(r.run_dir, s) for r, s in done]) if done else None
        if agg is not None:
            agg["training_arguments"] = list(group.arguments)
        result["groups"][group.name] = {
            "layout": group.layout, "setting": group.setting, "arguments": list(group.arguments),
            "seeds": [r.seed for r in runs if r.group == group.name], "aggregate": agg,
            "training_minutes": sweep_table.training_minutes(summaries)}
    return result


def write_results(out: str, result: dict) -> str:
    """OUT/sweep.json and OUT/sweep.md, each whole or not at all; returns the Markdown."""
    text = sweep_table.sweep_markdown(result)
    write_text(os.path.join(out, "sweep.json"), json.dumps(result, indent=1) + "\n")
    write_text(os.path.join(out, "sweep.md"), text)
    return text


def main(argv=None) -> dict:
    """Parse, check, run what is missing, write the table; returns sweep.json's content."""
    args, passthrough = build_parser().parse_known_args(argv)
    sweep_ray.check_installed()
    outputs.check_directory(args.out)
    groups, runs = plan(args, passthrough)
    if args.address is not None:
        sweep_ray.check_reachable(args.address)
    with directory_lock.lock_directory(args.out, PROG):  # released, and its file removed, however this ends
        return _sweep(args, argv, groups, runs)


def _sweep(args, argv, groups, runs) -> dict:
    """The sweep in its locked directory: run what is missing, write the table."""
    check_recorded_groups(args.out, groups)
    command = [PROG, *(sys.argv[1:] if argv is None else argv)]
    pending = [run for run in runs if not run.finished()]
    for run in runs:  # a finished run's damaged summary stops the sweep now, not when it tabulates
        if run.finished():
            parsing.read_json(run.summary_path)
    print(f"{PROG}: {len(runs) - len(pending)} of {len(runs)} runs finished, {len(pending)} to run "
          f"({sum(r.has_checkpoint() for r in pending)} resumed) in {args.out}", file=sys.stderr, flush=True)
    outcomes = {}
    if pending:
        sweep_ray.train_command()  # on this machine at least: a missing command is one line, not N failures
        with sweep_ray.connected(args.out, args.address, args.num_cpus) as ray:
            outcomes = run_all(ray, pending, len(runs), len(runs) - len(pending), args.quiet,
                               lambda o: write_results(args.out, collect(args.out, groups, runs, o, command)))
    result = collect(args.out, groups, runs, outcomes, command)
    print(write_results(args.out, result), end="")
    for failure in result["failed"]:
        print(f"{PROG}: run {failure['group']} seed {failure['seed']} failed: {failure['error']}", file=sys.stderr)
    print(f"wrote {os.path.join(args.out, 'sweep.md')} and sweep.json", file=sys.stderr)
    return result


def cli(argv=None) -> int:
    """Console script: 0 when every run finished, 1 when a run failed (each named on stderr), 2 with
    one line on a bad input, 130 on Ctrl-C (robostrich_suite.cli)."""
    results = []
    status = cli_lib.run(lambda a: results.append(main(a)), PROG, argv)
    if status == 0 and results and (results[0]["failed"] or results[0]["finished"] < results[0]["total"]):
        return 1
    return status


if __name__ == "__main__":
    sys.exit(cli())
