"""robostrich-design: search tendon routings for the paper's tests and the narrow gap.

    robostrich-design --trials 200 --out out/design            # resumable: run it again to go on
    robostrich-design --trials 0 --confirm 3 --out out/design  # full measures of the front's best 3

The space is :mod:`robostrich_suite.studies.design_space` (Table 1's links, one dorsal and eight
ventral tendons through run-through holes; origins, insertions and hole offsets searched).
Each trial is scored cheaply (:mod:`robostrich_suite.studies.design_objectives`, ``--pose-budget``).

**Beyond the paper's family**: ``--ventral-tendons N`` (2-16) and ``--dorsal-tendons M``
(1-4) change the tendon counts, and ``--max-hole-stride K`` (1-4) lets each tendon's holes be up to
K links apart, skipping the links between (``design_space.Space``: the one other insertion the
generator builds as it is; a tendon tied at two links short of the base is already in the family).
More tendons are more servos: the written layout files give the tasks a larger action spec.  All
three are fixed for a study, as ``--pose-budget`` is, and ``--start-from`` must fit them.

**Two objectives and one constraint.**  Maximised: the share of the blue region held level
(coverage) and the height of the gap column (the narrow gap's measure).  Constrained: the
rolling/lever attitude ratio at most :data:`design_study.RATIO_LIMIT`, the paper's "well below 1" made a
number (the Fig. 1B candidates measure 0.31-0.42; routings from the base 1.25-2).  The ratio is a
test the paper's arm passes, not a quantity to trade, so it bounds the search instead of
spreading the front over a third axis; coverage and the gap column do trade (a neck that rises
under its head reaches less of the region in front), and the front shows how.

**The slot where the task puts it, and the way in** (docs/layouts.md).  Left free, the search
finds its columns over the mount, where no ramp from under the shelf gets in.
``--slot-x MIN,MAX`` holds the slot's centre in that range (m ahead of the base joint; the task's
is ``gap_column.TASK_NEED["slot_x_m"]``, 0.36 m); ``--score-passage`` replaces the second objective
by the way in (``design_objectives.passage_score``): how far up through the slot the head gets
from under the shelf before anything touches (m from the shelf's top), plus the column's height
when a ramp reaches the column; a head never over the slot scores the floor (the ground) less how
far in x it stayed from the slot.  A column nobody can enter is worth nothing to the task, and a
pass/fail count would be 0 for every routing the first search found: the height is graded, so the
sampler can climb towards a way in before any exists.  The ramps go into the column's lowest pose;
with no column in the range, into the highest held pose whose head is over the range (level ones
first, the slot under it); with none, the floor less 1 m.  It costs 100 draws and 6 ramps a trial
(``design_objectives.PASSAGE_SAMPLES``), about a quarter of a trial.  Both flags are fixed for a
study, as ``--pose-budget`` is; a negative MIN is written ``--slot-x=-0.1,0.1``.

**Multi-objective TPE** (Optuna's ``TPESampler`` with ``constraints_func``; ``constant_liar`` so
that several machines on one ``--storage`` do not all try the same routing): with a few hundred
trials of ~10 s it is the more sample-efficient choice; NSGA-II needs generations of a population
each larger than that budget allows to do better than random draws.

The study lives in Optuna's RDB storage (SQLite in ``OUT/study.db`` unless ``--storage`` names any
SQLAlchemy URL): each trial is committed when it ends, so Ctrl-C or a killed machine keeps every
finished trial, and the running one is marked failed (by the command, or by the heartbeat from
another process); the same command again resumes until ``--trials`` trials are complete.

Writes into ``--out``: ``front.png`` (the Pareto front), ``design.json`` (the front, the trials'
rate, the gap column the task needs; ``tools/results_page.py add NAME OUT/design.json`` records
it) and ``layouts/trial_N.json`` (the front's routings as layout files, for ``--layout-file`` and
``task_kwargs={"tendon_layout": path}``); with ``--confirm K`` the full measures of the front's best
K (``robostrich-layouts``' coverage, movement tests and targets, the gap measure at
``design_objectives.FULL``) are kept in the study and go into ``design.json`` too.
"""
from __future__ import annotations

import pathlib
import shlex
import sys
import warnings

from robostrich_suite import cli as cli_lib
from robostrich_suite import outputs
from robostrich_suite.studies import design_report, design_space, design_study

PROG = "robostrich-design"
SLOT_X_LIMIT = 1.0  # m: --slot-x within this of the base joint
MAX_TRIALS = 100_000
MAX_POSE_BUDGET = 2_000
MIN_POSE_BUDGET = 6  # two coverage cells, three column targets, one to grow a column


def slot_range(text: str) -> tuple:
    """argparse type for --slot-x: 'MIN,MAX', finite, MIN < MAX, within +-SLOT_X_LIMIT m."""
    import argparse
    import math
    parts = text.split(",")
    try:
        low, high = (float(part) for part in parts) if len(parts) == 2 else (math.nan, math.nan)
    except ValueError:
        low = high = math.nan
    if not (math.isfinite(low) and math.isfinite(high)):
        raise argparse.ArgumentTypeError(f"must be two numbers MIN,MAX (m), got {text!r}")
    if not low < high:
        raise argparse.ArgumentTypeError(f"MIN must be below MAX, got {text}")
    if max(abs(low), abs(high)) > SLOT_X_LIMIT:
        raise argparse.ArgumentTypeError(f"must lie within -{SLOT_X_LIMIT:g} to {SLOT_X_LIMIT:g} m, got {text}")
    return low, high


MAX_STUDY_NAME = 200  # characters: Optuna's storages keep names of up to 512


def study_name(text: str) -> str:
    """argparse type for --study-name: a name with something to read in it, on one line."""
    import argparse
    if not text.strip() or len(text) > MAX_STUDY_NAME or not text.isprintable():
        raise argparse.ArgumentTypeError(f"must be a printable name of 1 to {MAX_STUDY_NAME} characters, got {text!r}")
    return text


def build_parser() -> cli_lib.Parser:
    parser = cli_lib.Parser(prog=PROG, description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=cli_lib.whole_number(0, MAX_TRIALS), default=100,
                        help="complete trials the study should hold; a resumed study runs only the rest "
                             "(0: write the outputs of the study as it is) (default: %(default)s)")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/design"),
                        help="output directory (default: %(default)s)")
    parser.add_argument("--storage", default=None,
                        help="Optuna storage URL, e.g. sqlite:///study.db or postgresql://... for several "
                             "machines on one study (default: sqlite:///OUT/study.db)")
    parser.add_argument("--study-name", type=study_name, default="robostrich-design",
                        help="the study's name (default: %(default)s)")
    parser.add_argument("--seed", type=cli_lib.seed, default=0,
                        help="the sampler's seed (offset by the trials already in the study) (default: %(default)s)")
    parser.add_argument("--pose-budget", type=cli_lib.whole_number(MIN_POSE_BUDGET, MAX_POSE_BUDGET), default=36,
                        help="sought poses per trial, fixed for a study (default: %(default)s)")
    parser.add_argument("--search-stiffness", action="store_true",
                        help="search the passive joint stiffness too (0.5-4 N m/rad), fixed for a study")
    parser.add_argument("--slot-x", type=slot_range, default=None, metavar="MIN,MAX",
                        help="the gap's slot centred within MIN..MAX m ahead of the base joint, fixed for a study "
                             "(default: anywhere; the task's slot is at 0.36; a negative MIN: --slot-x=-0.1,0.1)")
    parser.add_argument("--score-passage", action="store_true",
                        help="the second objective becomes the way into the gap instead of the column's height: how "
                             "far up through the slot the head gets from under the shelf before anything touches (m "
                             "from the shelf's top), plus the column's height once a way reaches it; fixed for a study")
    parser.add_argument("--dorsal-tendons", type=cli_lib.whole_number(*design_space.DORSAL_RANGE),
                        default=design_space.DORSAL_TENDONS, metavar="M",
                        help="dorsal tendons per routing, fixed for a study (default: %(default)s, the paper's)")
    parser.add_argument("--ventral-tendons", type=cli_lib.whole_number(*design_space.VENTRAL_RANGE),
                        default=design_space.VENTRAL_TENDONS, metavar="N",
                        help="ventral tendons per routing, fixed for a study (default: %(default)s, the paper's)")
    parser.add_argument("--max-hole-stride", type=cli_lib.whole_number(*design_space.STRIDE_RANGE), default=1,
                        metavar="K", help="search each tendon's holes every 1..K links (K > 1: holes that skip "
                                          "links), fixed for a study (default: %(default)s, the paper's: every link)")
    parser.add_argument("--start-from", nargs="+", default=[], metavar="LAYOUT",
                        help="built-in layouts or layout files tried first, when the study is new (each must be "
                             "in the space: the tendon counts asked, holed every link or every K; default: none)")
    parser.add_argument("--confirm", type=cli_lib.whole_number(0, 50), default=0, metavar="K",
                        help="full measures of the front's best K routings (by gap column, then coverage; "
                             "default: %(default)s)")
    parser.add_argument("--no-progress", "--quiet", dest="quiet", action="store_true",
                        help="no progress bar, only the summary")
    return parser


def main(argv=None) -> dict:
    args = build_parser().parse_args(argv)
    space = design_space.Space(args.dorsal_tendons, args.ventral_tendons, args.max_hole_stride)
    starts = [design_study.start_layout(item, space) for item in args.start_from]  # bad ones fail before any work
    outputs.check_directory(args.out)
    args.out.mkdir(parents=True, exist_ok=True)
    storage_url = args.storage or f"sqlite:///{(args.out / 'study.db').resolve()}"
    settings = design_study.Settings(args.pose_budget, args.search_stiffness, args.slot_x, args.score_passage, space)
    study = design_study.open_study(storage_url, args.study_name, settings, args.seed)
    command = shlex.join([PROG, *(sys.argv[1:] if argv is None else argv)])
    with cli_lib.deferred_interrupts():
        design_study.enqueue_once(study, starts, args.search_stiffness)
        design_study.run_trials(study, args.trials, settings, show_progress=not args.quiet)
        if cli_lib.interrupted():
            raise KeyboardInterrupt
    # Outside the deferral: Ctrl-C stops a confirmation at once; each routing's measures are kept as it ends.
    confirmed = design_study.confirm(study, args.confirm, args.out, show_progress=not args.quiet)
    summary = design_report.write(study, args.out, command, storage_url, confirmed)
    design_report.print_summary(summary, args.out)
    return summary


def cli(argv=None) -> int:
    """Exit status 0, 2 with one line on bad input, 130 on Ctrl-C, 143 on SIGTERM (robostrich_suite.cli)."""
    warnings.filterwarnings("ignore", module="optuna")
    return cli_lib.run(main, PROG, argv)


if __name__ == "__main__":
    sys.exit(cli())
