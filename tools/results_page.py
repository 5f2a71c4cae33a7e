"""The results page and the README's results table, generated from committed result records.

    python tools/results_page.py add main_job runs/sweep/sweep.json --group ventral_slips \\
        --title "The main job on the paper's robot"
    python tools/results_page.py add main_job runs/seeds_main/seeds.json \\
        --title "The main job on the paper's robot" --command "python tools/benchmark_seeds.py --seeds 0,1,2,3"
    python tools/results_page.py            # rewrite docs/results.md and the README's table
    python tools/results_page.py --check    # exit 1 when either differs from the records

A record (docs/results/NAME.json) keeps what a benchmark wrote (one group of robostrich-sweep's
sweep.json, or an earlier tools/benchmark_seeds.py seeds.json), the command that made it, the date
and the machine. Numbers are typed nowhere else:
the page and the README's table are rendered from the records, and tests/test_results_page.py
fails when the committed text differs from what the records give.
"""
import argparse
import datetime
import json
import os
import pathlib
import platform
import shlex
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
RECORDS = ROOT / "docs" / "results"
PAGE = ROOT / "docs" / "results.md"
README = ROOT / "README.md"
FORMAT = 1
# A README block "<!-- results: NAME (...) --> ... <!-- /results -->" holds record NAME's table.
README_BEGIN = "<!-- results: {name} (tools/results_page.py writes this table) -->"
README_END = "<!-- /results -->"
README_RECORD = "main_job"  # the README's first table; others are placed by their blocks

RUNS = {"curriculum": "curriculum SAC", "baseline": "plain SAC (final lesson only)", "lookup": "lookup (no learning)"}
KINDS = {"heldout": "held-out, fixed start", "heldout_moving": "held-out, moving starts",
         "track": "`track` (3 targets in turn)"}
AFTER = "heldout_after_"  # the evaluation at the end of a lesson but the last


def kind_title(kind: str) -> str:
    if kind.startswith(AFTER):
        return f"held-out, fixed start, after {kind[len(AFTER):]}"
    return KINDS.get(kind, kind)


def machine() -> str:
    """Cores and CPU model: timings mean something only beside them."""
    model = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            model = next((line.split(":", 1)[1].strip() for line in f if line.startswith("model name")), model)
    except OSError:
        pass
    return f"{os.cpu_count()} cores, {model}"


def sweep_group(sweep: dict, path: str, group: str = None) -> tuple:
    """(aggregate, command) of one group of a robostrich-sweep sweep.json: ``group``, or its only one."""
    groups = sweep["groups"]
    if group is None and len(groups) != 1:
        raise ValueError(f"{path} holds groups {', '.join(groups)}: name one with --group")
    name = group if group is not None else next(iter(groups))
    if name not in groups:
        raise ValueError(f"{path} has no group {name!r} (it has {', '.join(groups)})")
    if groups[name]["aggregate"] is None:
        raise ValueError(f"{path}: group {name} has no finished run")
    return groups[name]["aggregate"], shlex.join(sweep["command"])


def make_record(name: str, seeds_json: str, title: str, command: str = None, date: str = None, note: str = "",
                group: str = None) -> dict:
    """A record of a robostrich-sweep sweep.json (one group; its command unless ``command`` says) or
    of a tools/benchmark_seeds.py seeds.json of earlier benchmarks."""
    with open(seeds_json) as f:
        aggregate = json.load(f)
    if "groups" in aggregate and "command" in aggregate:
        aggregate, recorded = sweep_group(aggregate, seeds_json, group)
        command = command or recorded
    elif "results" not in aggregate or "seeds" not in aggregate:
        raise ValueError(f"{seeds_json} is not a tools/benchmark_seeds.py seeds.json nor a robostrich-sweep "
                         "sweep.json (no 'results'/'seeds', no 'groups')")
    elif group is not None:
        raise ValueError(f"--group {group}: {seeds_json} is a seeds.json of one group")
    if not command:
        raise ValueError(f"{seeds_json} records no command: give --command")
    return {"format": FORMAT, "name": name, "title": title, "command": command,
            "date": date or datetime.date.today().isoformat(), "machine": machine(), "note": note,
            "seeds": aggregate}


def read_records(directory: pathlib.Path = RECORDS) -> list:
    records = []
    for path in sorted(directory.glob("*.json")):
        with open(path) as f:
            record = json.load(f)
        if record.get("format") != FORMAT:
            raise ValueError(f"{path} has record format {record.get('format')}, this tool reads {FORMAT}")
        records.append(record)
    return sorted(records, key=lambda r: (r.get("order", 100), r["name"]))


def _cell(stats: dict, scale: float, unit: str, digits: int = 1) -> str:
    if stats["mean"] is None:
        return "-"
    mean, low, high = (f"{stats[k] * scale:.{digits}f}" for k in ("mean", "min", "max"))
    return f"{mean} {unit}" if low == high else f"{mean} {unit} [{low}, {high}]"


def partial_seeds(row: dict, seeds: int) -> str:
    """' (k of n seeds)' for a row evaluated on fewer seeds than its record has, else ''."""
    counted = row.get("seeds", seeds)
    return f" ({counted} of {seeds} seeds)" if counted != seeds else ""


def seeds_table(record: dict) -> list:
    """Markdown rows: every run and evaluation, mean [min, max] over the seeds."""
    lines = ["| run | evaluation | success | within 1 cm and 2 deg | median position error | median attitude error |",
             "|---|---|---|---|---|---|"]
    seeds = len(record["seeds"]["seeds"])
    for label, kinds in record["seeds"]["results"].items():
        for kind, row in kinds.items():
            lines.append(f"| {RUNS.get(label, label)} | {kind_title(kind)}{partial_seeds(row, seeds)} | "
                         f"{_cell(row['success_rate'], 100, '%')} | {_cell(row['precise_success_rate'], 100, '%')} | "
                         f"{_cell(row['position_error_median'], 100, 'cm', 2)} | "
                         f"{_cell(row['attitude_error_median'], 1, 'deg', 2)} |")
    return lines


def per_seed(record: dict) -> tuple:
    """(what the cells are, each seed's cells): the curriculum's success in every evaluation it has
    (`track` as targets reached of 3) and the wall-clock of the whole job."""
    agg = record["seeds"]
    curriculum = agg["results"].get("curriculum", {})
    kinds = ["heldout", "heldout_moving"] + ["track"] * ("track" in curriculum) + sorted(
        k for k in curriculum if k.startswith(AFTER))
    parts = []
    for i, seed in enumerate(agg["seeds"]):
        cells = []
        for kind in kinds:
            values = curriculum.get(kind, {}).get("success_rate", {}).get("values", [])
            if kind == "track":
                cells.append(f"{round(values[i] * 3)} of 3 track targets" if i < len(values) else "-")
            else:
                cells.append(f"{values[i] * 100:.1f} %" if i < len(values) else "-")
        minutes = agg["minutes"][i]
        cells.append(f"{minutes:.1f} min" if minutes is not None else "time unknown")
        parts.append(f"seed {seed}: " + " / ".join(cells))
    names = {"heldout": "held-out fixed", "heldout_moving": "moving", "track": "`track`"}
    header = " / ".join([names.get(k, f"after {k[len(AFTER):]}") for k in kinds] + ["wall-clock of the whole job"])
    return header, "; ".join(parts)


def budget(record: dict) -> str:
    """'curriculum SAC 600000, plain SAC ... 600000': the control steps each run trained."""
    return ", ".join(f"{RUNS.get(label, label)} {'/'.join(str(v) for v in sorted(set(filter(None, values))))}"
                     for label, values in record["seeds"]["steps"].items() if any(values))


def render_record(record: dict) -> str:
    agg = record["seeds"]
    lines = [f"## {record['title']}", "", f"`{record['command']}` ({record['date']}, {record['machine']}); "
             f"mean [min, max] over seeds {', '.join(map(str, agg['seeds']))}; control steps per run: {budget(record)}."]
    if record.get("note"):
        lines += ["", record["note"]]
    header, seeds = per_seed(record)
    lines += [""] + seeds_table(record) + ["", f"Curriculum SAC per seed ({header}): {seeds}."]
    return "\n".join(lines) + "\n"


def render_page(records: list) -> str:
    head = ("# Results\n\nGenerated by `python tools/results_page.py` from the records in `docs/results/` (what "
            "the benchmarks wrote, with their command, date and machine); do not edit by hand. Success is the "
            "paper's: the head within 5 cm and 5 deg of level at the episode's end. How these numbers were "
            "reached, and what did not help: [learning.md](learning.md).\n")
    return "\n".join([head] + [render_record(r) for r in records])


SHORT_KINDS = {"heldout": "held-out, fixed start", "heldout_moving": "moving starts", "track": "`track`"}


def short_table(record: dict) -> list:
    """The README's rows: one per run, the success of each evaluation (of the lesson ends, the last)
    and, from the fixed start, the precise share and the median errors; the page has every row."""
    results, seeds = record["seeds"]["results"], len(record["seeds"]["seeds"])
    present = {kind for kinds in results.values() for kind in kinds}
    after = sorted(k for k in present if k.startswith(AFTER))[-1:]
    kinds = [k for k in SHORT_KINDS if k in present] + after
    titles = [SHORT_KINDS.get(k, f"after {k[len(AFTER):]}") for k in kinds]
    lines = ["| run | " + " | ".join(titles) + " | within 1 cm and 2 deg | median error |",
             "|---|" + "---|" * (len(kinds) + 2)]
    for label, rows in results.items():
        partial = partial_seeds(rows.get("heldout", next(iter(rows.values()))), seeds)
        cells = [_cell(rows[k]["success_rate"], 100, "%") if k in rows else "-" for k in kinds]
        fixed = rows.get("heldout")
        cells += [_cell(fixed["precise_success_rate"], 100, "%"),
                  f"{fixed['position_error_median']['mean'] * 100:.2f} cm, "
                  f"{fixed['attitude_error_median']['mean']:.2f} deg"] if fixed else ["-", "-"]
        lines.append(f"| {RUNS.get(label, label)}{partial} | " + " | ".join(cells) + " |")
    return lines


def render_readme_table(record: dict) -> str:
    lines = [README_BEGIN.format(name=record["name"]),
             f"`{record['command']}` ({record['date']}), mean [min, max] over seeds "
             f"{', '.join(map(str, record['seeds']['seeds']))}; control steps per run: {budget(record)}:", ""]
    lines += short_table(record)
    lines += ["", README_END]
    return "\n".join(lines)


def readme_blocks(text: str) -> list:
    """The record names of the README's result blocks, in order."""
    import re
    pattern = re.escape(README_BEGIN).replace(re.escape("{name}"), r"([\w-]+)")
    return re.findall(pattern, text)


def replace_readme_table(text: str, table: str, name: str = README_RECORD) -> str:
    begin_marker = README_BEGIN.format(name=name)
    begin = text.find(begin_marker)
    end = text.find(README_END, begin)
    if begin < 0 or end < begin:
        raise ValueError(f"README.md has no '{begin_marker}' ... '{README_END}' block")
    return text[:begin] + table + text[end + len(README_END):]


def expected_files(records: list, readme_text: str) -> dict:
    by_name = {r["name"]: r for r in records}
    names = readme_blocks(readme_text)
    if README_RECORD not in names:
        names.insert(0, README_RECORD)  # and replace_readme_table says the block is missing
    readme = readme_text
    for name in names:
        if name not in by_name:
            raise ValueError(f"no record {name!r} in {RECORDS} for the README's table")
        readme = replace_readme_table(readme, render_readme_table(by_name[name]), name)
    return {PAGE: render_page(records), README: readme}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command")
    add = sub.add_parser("add", help="store a sweep's sweep.json (one group) or a seeds.json as a record in docs/results/")
    add.add_argument("name")
    add.add_argument("seeds_json", help="OUT/sweep.json of robostrich-sweep, or an earlier benchmark's seeds.json")
    add.add_argument("--title", required=True)
    add.add_argument("--group", default=None, help="the sweep's group to record (default: its only one)")
    add.add_argument("--command", dest="run_command", default=None,
                     help="the command that produced it (default: the one sweep.json records)")
    add.add_argument("--date", default=None, help="YYYY-MM-DD (default today)")
    add.add_argument("--note", default="", help="one paragraph shown under the title")
    add.add_argument("--order", type=int, default=100, help="position on the page (lower first)")
    p.add_argument("--check", action="store_true", help="exit 1 when the page or the README differs from the records")
    args = p.parse_args(argv)
    if args.command == "add":
        record = make_record(args.name, args.seeds_json, args.title, args.run_command, args.date, args.note,
                             args.group)
        record["order"] = args.order
        RECORDS.mkdir(parents=True, exist_ok=True)
        (RECORDS / f"{args.name}.json").write_text(json.dumps(record, indent=1) + "\n")
        print(f"wrote {RECORDS / (args.name + '.json')}")
        return 0
    expected = expected_files(read_records(), README.read_text())
    stale = [path for path, text in expected.items() if not path.exists() or path.read_text() != text]
    if args.check:
        for path in stale:
            print(f"{path.relative_to(ROOT)} differs from docs/results/*.json: run python tools/results_page.py",
                  file=sys.stderr)
        return 1 if stale else 0
    for path in stale:
        path.write_text(expected[path])
        print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except (ValueError, OSError) as error:
        print(f"results_page: error: {error}", file=sys.stderr)
        sys.exit(2)
