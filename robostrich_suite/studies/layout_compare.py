"""``robostrich-layouts``: tendon layouts (and passive joint stiffnesses) side by side.

With ``--candidates`` it is the fidelity check of the reconstructions of the paper's Fig. 1B
(:func:`layouts.fig1b_candidates`): the paper's own tests of its simulated arm, per candidate.

Every case is one routing on the same Table 1 links.  Per case:

* **coverage**: the share of the kinematic blue-region cells (Fig. 6, head at
  90 +- 5 deg; :mod:`robostrich_suite.studies.coverage`) in which the actuated arm holds its
  head level, from two samplers run alike for every case: random held inputs with
  the dorsal input tuned for a level head (``target_generation.generate``'s way) and one sought
  pose per blue sample (:mod:`robostrich_suite.studies.pose_seek`);
* **distinct level targets**: the held level poses at least 1 cm apart (the
  tasks' target spacing); they are written as the case's own target file;
* **rolling / lever**: the movement tests' attitude ranges at equal head travel and
  their ratio (:mod:`robostrich_suite.studies.movement`; the layout's ventral tendons ramped
  caudal to cranial, its most cranial dorsal tendon's input held);
* **lookup** (the installed command, from the agent's side: ``agents/robostrich/layouts.py``):
  held-out success of the no-learning baseline (nearest stored level pose, hold its inputs) on
  the case's own targets; with ``--train``, the held-out success of a short curriculum run of
  ``robostrich-train``'s learner too.

Writes ``layouts.md``, ``layouts.csv``, ``layouts.json`` (the rows with the command and the blue
region, what ``tools/results_page.py add`` records), ``layouts.png`` (blue region with the held
level poses, and the routing on a stick figure, per case) and ``targets/CASE.npz``.
"""
from __future__ import annotations

import csv
import dataclasses
import json
import pathlib
import re
import shlex
import sys
import time


from robostrich_suite import atomic_files
from robostrich_suite import cli as cli_lib
from robostrich_suite import outputs
from robostrich_suite import targets
from robostrich_suite.model import arm as arm_lib
from robostrich_suite import fingerprint as fingerprint_lib
from robostrich_suite.model import layouts as layouts_lib
from robostrich_suite.studies import coverage as coverage_lib
from robostrich_suite.studies import movement, pose_seek, target_generation, workspace
from robostrich_suite.studies import layout_figure

PROG = "robostrich-layouts"
DEFAULT_KINEMATIC_SAMPLES = 100_000  # the blue region: workspace.kinematic_samples(100000)
DEFAULT_RANDOM_SAMPLES = 300
RANDOM_CHUNK = 10  # random samples per progress update


@dataclasses.dataclass(frozen=True)
class Case:
    """One routing on one arm spec, under a label for the table and the figure."""
    label: str
    layout_name: str
    spec: arm_lib.ArmSpec
    layout: arm_lib.TendonLayout
    source: str  # "built-in" or the layout file


@dataclasses.dataclass(frozen=True)
class Options:
    random_samples: int = DEFAULT_RANDOM_SAMPLES
    seek_time: float = pose_seek.SEEK_TIME
    seed: int = 0
    movement: bool = True
    out: pathlib.Path = pathlib.Path("out/layouts")
    # Further measures of a case, in order: ``measure(case, target_path, options) -> dict`` of
    # columns (the held-out success of policies on the case's targets, from the agent's side).
    measures: tuple = ()

    def units(self, region: coverage_lib.BlueRegion) -> int:
        """Progress units of one case: one per sampled pose, one per later stage."""
        return self.random_samples + len(region.head_position) + self.movement + len(self.measures)


# --------------------------------------------------------------------------- measures

@dataclasses.dataclass(frozen=True)
class _LayoutMovement(movement.MovementConfig):
    """A movement test on a given layout (MovementConfig picks its own from ``ventral_span``)."""
    tendon_layout: arm_lib.TendonLayout | None = None

    def layout(self, spec: arm_lib.ArmSpec) -> arm_lib.TendonLayout:
        return self.tendon_layout


def movement_layout(layout: arm_lib.TendonLayout, spec: arm_lib.ArmSpec):
    """The layout renamed the way the movement tests find their tendons (the most cranial
    dorsal tendon ``dorsal``, the ventral ones ``ventral_i`` caudal to cranial, other
    dorsal ones ``extra_i``), or None without a dorsal and two ventral tendons."""
    rank = {name: i for i, name in enumerate(reversed(spec.joint_names))}  # caudal = 0
    dorsal = sorted((t for t in layout.tendons if t.side == "dorsal"), key=lambda t: rank[t.insertion])
    ventral = sorted((t for t in layout.tendons if t.side == "ventral"), key=lambda t: rank[t.insertion])
    if not dorsal or len(ventral) < 2:
        return None
    renamed = [dataclasses.replace(dorsal[-1], name="dorsal")]
    renamed += [dataclasses.replace(t, name=f"extra_{i}") for i, t in enumerate(dorsal[:-1])]
    renamed += [dataclasses.replace(t, name=f"ventral_{i}") for i, t in enumerate(ventral)]
    return arm_lib.TendonLayout(tuple(renamed))


def movement_ratio(case: Case, iterations: int = 7) -> dict:
    """Rolling and lever attitude ranges at equal head travel (the movement tests' defaults;
    ``iterations`` of the lever amplitude's bisection: fewer is a cheaper, coarser match)."""
    layout = movement_layout(case.layout, case.spec)
    if layout is None:
        return {"rolling_range_deg": None, "lever_range_deg": None, "rolling_lever_ratio": None,
                "head_travel_mm": None}
    rolling = movement.run(_LayoutMovement(tendon_layout=layout), case.spec)
    lever = _LayoutMovement(pattern="lever", tendon_layout=layout)
    amplitude = movement.match_lever_amplitude(lever, rolling.head_travel(), case.spec, iterations)
    lever = movement.run(dataclasses.replace(lever, lever_amplitude=amplitude), case.spec)
    ratio = rolling.attitude_range() / max(lever.attitude_range(), 1e-9)
    return {"rolling_range_deg": rolling.attitude_range(), "lever_range_deg": lever.attitude_range(),
            "rolling_lever_ratio": ratio, "head_travel_mm": 1000 * rolling.head_travel()}


def measure(case: Case, region: coverage_lib.BlueRegion, options: Options, progress=None) -> dict:
    """Every measure of one case; ``progress(n)`` advances a bar by n units."""
    progress = progress or (lambda n: None)
    random = []
    for start in range(0, options.random_samples, RANDOM_CHUNK):  # chunks: the bar moves
        size = min(RANDOM_CHUNK, options.random_samples - start)
        random.append(workspace.actuated_samples(size, [options.seed, start], pose_seek.HOLD_TIME,
                                                 seek_level_time=target_generation.SEEK_LEVEL_TIME,
                                                 spec=case.spec, layout=case.layout))
        progress(size)
    sought = pose_seek.seek_samples(region.head_position, region.joint_angles, case.spec,
                                    case.layout, options.seek_time, progress=progress)
    samples = workspace.ActuatedSamples.concatenate([*random, sought])
    level = samples.level()
    held = samples.head_position[level]
    covered = region.covered(held)
    target_path = options.out / "targets" / f"{case.label}.npz"
    target_generation.save_level_poses(target_path, dict(head_position=held,
                                               head_attitude=samples.head_attitude[level],
                                               control=samples.control[level]),
                             fingerprint_lib.model_fingerprint(case.spec, case.layout), allow_empty=True)
    row = {"layout": case.label, "source": case.source,
           "joint_stiffness": case.spec.joint_stiffness, "tendons": len(case.layout),
           "blue_cells": region.num_cells, "covered_cells": int(covered.sum()),
           "coverage": float(covered.mean()) if region.num_cells else 0.0,
           "level_poses": int(level.sum()), "level_poses_sought": int(sought.level().sum()),
           "distinct_targets": len(targets.distinct_indices(held)) if len(held) else 0,
           "target_file": str(target_path)}
    if options.movement:
        row.update(movement_ratio(case))
        progress(1)
    row["heldout_targets"] = len(targets.heldout_targets(target_path)) if len(held) else 0
    for extra in options.measures:
        row.update(extra(case, target_path, options))
        progress(1)
    return {"row": row, "held": held, "covered": covered}


def _measure_job(args):
    case, region, options, queue = args
    return measure(case, region, options, progress=queue.put)


def measure_all(cases, region, options: Options, workers: int = 1, show_progress: bool = True):
    """``measure`` every case (over ``workers`` processes), with one progress bar."""
    from tqdm import tqdm
    bar = tqdm(total=len(cases) * options.units(region), desc="layouts", unit="step",
               disable=not show_progress, mininterval=1.0)
    try:
        if workers <= 1 or len(cases) == 1:
            results = []
            for case in cases:
                bar.set_postfix_str(case.label)
                results.append(measure(case, region, options, progress=bar.update))
            return results
        import multiprocessing
        import queue as queue_lib
        from concurrent.futures import ProcessPoolExecutor
        with multiprocessing.Manager() as manager, ProcessPoolExecutor(min(workers, len(cases))) as pool:
            queue = manager.Queue()
            futures = [pool.submit(_measure_job, (case, region, options, queue)) for case in cases]
            while not all(f.done() for f in futures):
                try:
                    bar.update(queue.get(timeout=0.5))
                except queue_lib.Empty:
                    pass
            while not queue.empty():
                bar.update(queue.get())
            return [f.result() for f in futures]
    finally:
        bar.close()


# --------------------------------------------------------------------------- cases, tables

def make_cases(names, files, stiffnesses) -> list[Case]:
    """Built-ins ``names`` and layout ``files`` on Table 1's arm at each passive stiffness
    (None: the arm's own); a label per case, unique."""
    default = arm_lib.ArmSpec.from_table1()
    stiffnesses = list(stiffnesses) or [default.joint_stiffness]
    cases = []
    for stiffness in stiffnesses:
        spec = arm_lib.ArmSpec.from_table1(joint_stiffness=float(stiffness))
        spec.validate()
        suffix = "" if len(stiffnesses) == 1 else f"@k{float(stiffness):g}"
        layouts = [(name, layouts_lib.build(name, spec), "built-in") for name in names]
        for path in files:
            name, layout = layouts_lib.read_file(path, spec)
            layouts.append((name, layout, str(path)))
        for name, layout, source in layouts:
            if len(layout) > layouts_lib.MAX_FILE_TENDONS:
                raise ValueError(f"layout {name!r} ({source}) has {len(layout)} tendons; the "
                                 f"comparison takes {layouts_lib.MAX_FILE_TENDONS} servos at most")
            cases.append(Case(f"{name}{suffix}", name, spec, layout, source))
    labels = [c.label for c in cases]
    duplicates = sorted({x for x in labels if labels.count(x) > 1})
    if duplicates:
        raise ValueError(f"two layouts are called {duplicates}; give each file its own 'name'")
    return cases


COLUMNS = (  # (row key, table heading, format)
    ("layout", "layout", "{}"),
    ("joint_stiffness", "stiffness (N m/rad)", "{:g}"),
    ("tendons", "tendons", "{}"),
    ("covered_cells", "blue cells held", "{}"),
    ("blue_cells", "blue cells", "{}"),
    ("coverage", "coverage", "{:.0%}"),
    ("level_poses", "level poses held", "{}"),
    ("distinct_targets", "distinct level targets", "{}"),
    ("head_travel_mm", "head travel (mm)", "{:.0f}"),
    ("rolling_range_deg", "rolling range (deg)", "{:.1f}"),
    ("lever_range_deg", "lever range (deg)", "{:.1f}"),
    ("rolling_lever_ratio", "rolling / lever", "{:.2f}"),
    ("heldout_targets", "held-out targets", "{}"),
    ("lookup_success", "lookup held-out success", "{:.0%}"),
    ("curriculum_success", "curriculum held-out success", "{:.0%}"),
)


def _columns(rows):
    return [c for c in COLUMNS if any(c[0] in row for row in rows)]


def markdown_table(rows) -> str:
    columns = _columns(rows)
    lines = ["| " + " | ".join(c[1] for c in columns) + " |",
             "|" + "|".join("---" for _ in columns) + "|"]
    for row in rows:
        cells = ["n/a" if row.get(key) is None else fmt.format(row[key]) for key, _, fmt in columns]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def describe_samples(blue: dict) -> str:
    """One line: the blue region and the samples each layout got (a table's caption)."""
    return (f"Blue region: {blue['level_heads']} level heads among {blue['kinematic_samples']} kinematic samples, "
            f"{blue['cells']} cells of {blue['cell_size_m'] * 100:g} cm; {blue['random_samples']} random + "
            f"{blue['level_heads']} sought poses per layout.")


def write_csv(path: pathlib.Path, rows) -> None:
    keys = list(dict.fromkeys(key for row in rows for key in row))
    with atomic_files.replaced_atomically(path, "w") as f:
        writer = csv.DictWriter(f, fieldnames=keys)
        writer.writeheader()
        writer.writerows(rows)


# --------------------------------------------------------------------------- command line

def _plain(docstring: str) -> str:
    """A layout's docstring as --help text: one line, Sphinx roles as their names, no final stop."""
    return re.sub(r":\w+:`~?([^`]+)`", r"\1", " ".join(docstring.split())).rstrip(".")


def build_parser() -> cli_lib.Parser:
    """The command's options; the agent's side (agents/robostrich/layouts.py) adds its own."""
    parser = cli_lib.Parser(
        prog=PROG,
        description="Compare tendon layouts (and passive joint stiffnesses) of the Robostrich "
                    "arm on the same Table 1 links: share of the blue region of Fig. 6 (where the links "
                    "can put the head level, 90+-5 deg) held level by the tendons (coverage), distinct "
                    "level targets, rolling/lever attitude ranges, "
                    "and, from the agent's side, held-out success of the lookup baseline (and, "
                    "with --train, of a short curriculum run). Writes layouts.md, layouts.csv, layouts.png and "
                    "targets/LAYOUT.npz under --out.",
        epilog="built-in layouts: " + " ".join(f"{name}: {_plain(b.description)}."
                                                 for name, b in layouts_lib.BUILT_IN.items())
               + " Layout files (--layout-file): " + cli_lib.doc_excerpt(
                   layouts_lib.__doc__, "JSON or TOML", "::", {
                       "arm.HOLE_OFFSET_RANGE": "{:g}-{:g} m".format(*arm_lib.HOLE_OFFSET_RANGE),
                       ", as TendonSpec.spanning": ""})
               + ", for example " + layouts_lib.example_file())
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/layouts"),
                        help="output directory (default: %(default)s)")
    parser.add_argument("--layouts", nargs="*", default=list(layouts_lib.BUILT_IN),
                        choices=list(layouts_lib.BUILT_IN), metavar="NAME",
                        help="built-in layouts to compare (default: all of them)")
    parser.add_argument("--candidates", action="store_true",
                        help="the fidelity check: compare the built-in candidate reconstructions of the "
                             "paper's Fig. 1B (one dorsal tendon to the head, eight ventral tendons at "
                             "C16, C14, ..., C2: " + ", ".join(layouts_lib.fig1b_candidates())
                             + ") instead of --layouts")
    parser.add_argument("--layout-file", nargs="+", default=[], type=pathlib.Path, metavar="FILE",
                        help="also compare layouts from JSON/TOML files (their format: below; default: none)")
    parser.add_argument("--stiffness", nargs="+", type=cli_lib.number(1e-6, 1e4, " N m/rad"), default=[],
                        metavar="N_M_PER_RAD",
                        help="passive joint stiffnesses to sweep, every layout at each "
                             "(default: the arm's own)")
    parser.add_argument("--kinematic-samples", type=cli_lib.whole_number(1), default=DEFAULT_KINEMATIC_SAMPLES,
                        help="uniform kinematic samples that make the blue region (default: %(default)s)")
    parser.add_argument("--random-samples", type=cli_lib.whole_number(0), default=DEFAULT_RANDOM_SAMPLES,
                        help="random held inputs per case, dorsal tuned for a level head "
                             "(default: %(default)s)")
    parser.add_argument("--seek-time", type=cli_lib.seconds(), default=pose_seek.SEEK_TIME,
                        help="seconds of input adjustment per sought blue-region pose "
                             "(default: %(default)s)")
    parser.add_argument("--seed", type=cli_lib.seed, default=0, help="random seed (default: %(default)s)")
    parser.add_argument("--no-movement", action="store_true", help="skip the rolling/lever tests")
    parser.add_argument("--workers", type=cli_lib.whole_number(1, cli_lib.MAX_WORKERS), default=1,
                        help="processes, one case each (default: %(default)s)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    return parser


def main(argv=None, parser=None, measures_from_args=lambda args: ()) -> dict:
    """Command line: measure the cases, write the table, the CSV, the figure and the targets.
    ``parser`` (default :func:`build_parser`) may carry more options, from which
    ``measures_from_args(args)`` makes the further measures of every case (``Options.measures``)."""
    parser = parser or build_parser()
    args = parser.parse_args(argv)
    if args.candidates:
        args.layouts = layouts_lib.fig1b_candidates()
    if not args.layouts and not args.layout_file:
        parser.error("nothing to compare: give --layouts and/or --layout-file")
    outputs.check_directory(args.out)
    start = time.perf_counter()
    cases = make_cases(args.layouts, args.layout_file, args.stiffness)
    options = Options(args.random_samples, args.seek_time, args.seed, not args.no_movement, args.out,
                      tuple(measures_from_args(args)))
    region = coverage_lib.BlueRegion.from_samples(
        workspace.kinematic_samples(args.kinematic_samples, args.seed, cases[0].spec))
    if region.num_cells == 0:
        raise ValueError(f"no level head among {args.kinematic_samples} kinematic samples; "
                         "raise --kinematic-samples")
    results = measure_all(cases, region, options, args.workers, not args.no_progress)
    figure = report(args, cases, region, results, shlex.join([PROG, *(sys.argv[1:] if argv is None else argv)]))
    print(f"done in {time.perf_counter() - start:.1f} s")
    return {"rows": [r["row"] for r in results], "figure": figure}


def report(args, cases, region, results, command: str) -> pathlib.Path:
    """Write layouts.md, layouts.csv and layouts.png under ``args.out`` and print the table."""
    rows = [r["row"] for r in results]
    args.out.mkdir(parents=True, exist_ok=True)
    table = markdown_table(rows)
    blue = {"level_heads": len(region.head_position), "kinematic_samples": args.kinematic_samples,
            "cells": region.num_cells, "cell_size_m": coverage_lib.CELL_SIZE,
            "random_samples": args.random_samples}
    atomic_files.write_text(args.out / "layouts.md", describe_samples(blue) + "\n\n" + table)
    write_csv(args.out / "layouts.csv", rows)
    atomic_files.write_text(args.out / "layouts.json", json.dumps(
        {"benchmark": "layouts", "command": command, "blue_region": blue, "rows": rows}, indent=1) + "\n")
    figure = layout_figure.plot(cases, region, results, args.out / "layouts.png")
    print(table, end="")
    best = max(rows, key=lambda row: row["coverage"])
    print(f"largest share of the blue region held: {best['layout']} ({best['coverage']:.0%})")
    for name in ("layouts.md", "layouts.csv", "layouts.json"):
        print(f"wrote {args.out / name}")
    print(f"wrote {figure}")
    print(f"wrote {args.out / 'targets'}/ (one target file per layout)")
    return figure


def cli(argv=None) -> int:
    """The comparison without the agent's measures: exit status 0, or 2 with a one-line error
    (robostrich_suite.cli); the installed ``robostrich-layouts`` is agents/robostrich/layouts.py's."""
    return cli_lib.run(main, PROG, argv)


if __name__ == "__main__":
    sys.exit(cli())
