"""The results page and every results table in README.md and docs/, generated from committed records.

    python tools/results_page.py add main_job runs/sweep/sweep.json --group ventral_slips \\
        --title "The main job on the paper's robot"
    python tools/results_page.py add dmc_check runs/dmc/dmc.json --title "The learner on dm_control"
    python tools/results_page.py add layouts out/layouts/layouts.json --title "Tendon routings compared"
    python tools/results_page.py add speed_env runs/speed_env.json --title "Environment speed"
    python tools/results_page.py            # rewrite docs/results.md and every block
    python tools/results_page.py --check    # exit 1 when any of them differs from the records

A record (docs/results/NAME.json) keeps what a benchmark wrote, the command that made it, the date
and the machine. Its kind says which benchmark: "seeds" (one group of robostrich-sweep's
sweep.json, or an earlier tools/benchmark_seeds.py seeds.json; tools/results_seeds.py renders it),
"dmc" (tools/benchmark_dmc.py's dmc.json), "layouts" (robostrich-layouts' layouts.json) or
"speed" (tools/benchmark_env.py, benchmark_a1.py or benchmark_learner.py with --json). Numbers are
typed nowhere else: the page and each block "<!-- results: NAME ... -->" in README.md or a page of
docs/ are rendered from the records, and tests/test_results_page.py fails when the committed text
differs from what the records give.
"""
import argparse
import datetime
import json
import os
import pathlib
import platform
import re
import sys

import results_dmc
import results_layouts
import results_seeds
import results_speed

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
from robostrich_suite import files  # noqa: E402  (the project's one atomic writer)

RECORDS = ROOT / "docs" / "results"
PAGE = ROOT / "docs" / "results.md"
README = ROOT / "README.md"
FORMAT = 2
# A block "<!-- results: NAME (...) --> ... <!-- /results -->" in README.md or a page of docs/
# holds record NAME's table.
BLOCK_BEGIN = "<!-- results: {name} (tools/results_page.py writes this table) -->"
BLOCK_END = "<!-- /results -->"
README_RECORD = "main_job"  # the README's first table, which it must have

KINDS = {"seeds": results_seeds, "dmc": results_dmc, "layouts": results_layouts, "speed": results_speed}


def machine() -> str:
    """Cores and CPU model: timings mean something only beside them."""
    model = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            model = next((line.split(":", 1)[1].strip() for line in f if line.startswith("model name")), model)
    except OSError:
        pass
    return f"{os.cpu_count()} cores, {model}"


def kind_of(data: dict) -> str:
    """What wrote ``data``: a benchmark's own 'benchmark' key, else the seeds (or sweep) aggregate."""
    return data["benchmark"] if data.get("benchmark") in KINDS else "seeds"


def make_record(name: str, path: str, title: str, command: str = None, date: str = None, note: str = "",
                group: str = None) -> dict:
    """A record of what a benchmark wrote: one group of a robostrich-sweep sweep.json (or an earlier
    tools/benchmark_seeds.py seeds.json), tools/benchmark_dmc.py's dmc.json, robostrich-layouts'
    layouts.json or a speed benchmark's --json file; the command it records unless ``command`` says."""
    with open(path) as f:
        written = json.load(f)
    kind = kind_of(written)
    data, recorded = KINDS[kind].read(written, path, group)
    command = command or recorded
    if not command:
        raise ValueError(f"{path} records no command: give --command")
    return {"format": FORMAT, "name": name, "title": title, "kind": kind, "command": command,
            "date": date or datetime.date.today().isoformat(), "machine": machine(), "note": note, "data": data}


def read_records(directory: pathlib.Path = RECORDS) -> list:
    records = []
    for path in sorted(directory.glob("*.json")):
        with open(path) as f:
            record = json.load(f)
        if record.get("format") != FORMAT:
            raise ValueError(f"{path} has record format {record.get('format')}, this tool reads {FORMAT}")
        if record.get("kind") not in KINDS:
            raise ValueError(f"{path} has kind {record.get('kind')!r}; known: {', '.join(KINDS)}")
        records.append(record)
    return sorted(records, key=lambda r: (r.get("order", 100), r["name"]))


def render_record(record: dict) -> str:
    """The page's section: title, command, date, machine, what the cells are, the note, every row."""
    kind = KINDS[record["kind"]]
    lines = [f"## {record['title']}", "",
             f"`{record['command']}` ({record['date']}, {record['machine']}); {kind.caption(record['data'])}."]
    if record.get("note"):
        lines += ["", record["note"]]
    lines += [""] + kind.full(record["data"])
    return "\n".join(lines) + "\n"


def render_page(records: list) -> str:
    head = ("# Results\n\nGenerated by `python tools/results_page.py` from the records in `docs/results/` (what "
            "the benchmarks wrote, with their command, date and machine); do not edit by hand. Success is the "
            "paper's: the head within 5 cm and 5 deg of level at the episode's end. How these numbers were "
            "reached, and what did not help: [learning.md](learning.md).\n")
    return "\n".join([head] + [render_record(r) for r in records])


def render_block(record: dict) -> str:
    """A block in README.md or a page of docs/: the record's short table with its command and date."""
    kind = KINDS[record["kind"]]
    lines = [BLOCK_BEGIN.format(name=record["name"]),
             f"`{record['command']}` ({record['date']}), {kind.caption(record['data'])}:", ""]
    lines += kind.short(record["data"])
    lines += ["", BLOCK_END]
    return "\n".join(lines)


def blocks(text: str) -> list:
    """The record names of a text's result blocks, in order."""
    pattern = re.escape(BLOCK_BEGIN).replace(re.escape("{name}"), r"([\w-]+)")
    return re.findall(pattern, text)


def replace_block(text: str, block: str, name: str, where: str = "README.md") -> str:
    begin_marker = BLOCK_BEGIN.format(name=name)
    begin = text.find(begin_marker)
    end = text.find(BLOCK_END, begin)
    if begin < 0 or end < begin:
        raise ValueError(f"{where} has no '{begin_marker}' ... '{BLOCK_END}' block")
    return text[:begin] + block + text[end + len(BLOCK_END):]


def with_blocks(text: str, by_name: dict, where: str, required: tuple = ()) -> str:
    """``text`` with each of its blocks (and each ``required`` one) rendered from its record."""
    names = blocks(text)
    names += [name for name in required if name not in names]  # and replace_block says it is missing
    for name in names:
        if name not in by_name:
            raise ValueError(f"no record {name!r} in {RECORDS} for the table in {where}")
        text = replace_block(text, render_block(by_name[name]), name, where)
    return text


def block_pages(root: pathlib.Path = ROOT) -> list:
    """The pages that may hold blocks: the README and every page of docs/ but the results page."""
    return [root / "README.md"] + sorted(p for p in (root / "docs").glob("*.md") if p.name != PAGE.name)


def expected_files(records: list, texts: dict) -> dict:
    """{path: text} of the results page and of every page in ``texts`` ({path: its text now}) with
    its blocks rendered from the records."""
    by_name = {r["name"]: r for r in records}
    expected = {PAGE: render_page(records)}
    for path, text in texts.items():
        required = (README_RECORD,) if path == README else ()
        expected[path] = with_blocks(text, by_name, path.name, required)
    return expected


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command")
    add = sub.add_parser("add", help="store what a benchmark wrote as a record in docs/results/")
    add.add_argument("name", help="the record's name (docs/results/NAME.json; a block names it)")
    add.add_argument("written", help="OUT/sweep.json of robostrich-sweep (or an earlier seeds.json), dmc.json of "
                     "tools/benchmark_dmc.py, layouts.json of robostrich-layouts, or a speed benchmark's --json file")
    add.add_argument("--title", required=True)
    add.add_argument("--group", default=None, help="the sweep's group to record (default: its only one)")
    add.add_argument("--command", dest="run_command", default=None,
                     help="the command that produced it (default: the one the file records)")
    add.add_argument("--date", default=None, help="YYYY-MM-DD (default today)")
    add.add_argument("--note", default="", help="one paragraph shown under the title")
    add.add_argument("--order", type=int, default=100, help="position on the page (lower first)")
    p.add_argument("--check", action="store_true", help="exit 1 when the page or a block differs from the records")
    args = p.parse_args(argv)
    if args.command == "add":
        record = make_record(args.name, args.written, args.title, args.run_command, args.date, args.note,
                             args.group)
        record["order"] = args.order
        RECORDS.mkdir(parents=True, exist_ok=True)
        files.write_text(RECORDS / f"{args.name}.json", json.dumps(record, indent=1) + "\n")
        print(f"wrote {RECORDS / (args.name + '.json')}")
        return 0
    expected = expected_files(read_records(), {path: path.read_text() for path in block_pages()})
    stale = [path for path, text in expected.items() if not path.exists() or path.read_text() != text]
    if args.check:
        for path in stale:
            print(f"{path.relative_to(ROOT)} differs from docs/results/*.json: run python tools/results_page.py",
                  file=sys.stderr)
        return 1 if stale else 0
    for path in stale:
        files.write_text(path, expected[path])
        print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except (ValueError, OSError) as error:
        print(f"results_page: error: {error}", file=sys.stderr)
        sys.exit(2)
