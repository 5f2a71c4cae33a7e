"""The results page and every results table in README.md and docs/, generated from committed records.

    python tools/results_page.py add main_job runs/sweep/sweep.json --group ventral_slips \\
        --title "The main job on the paper's robot"
    python tools/results_page.py add dmc_check runs/dmc/dmc.json --title "The learner on dm_control"
    python tools/results_page.py add layouts out/layouts/layouts.json --title "Tendon routings compared"
    python tools/results_page.py add speed_env runs/speed_env.json --title "Environment speed"
    python tools/results_page.py add design out/design/design.json --title "Routings searched"
    python tools/results_page.py add robustness_robostrich out/robustness/robustness.json --title "Robustness"
    python tools/results_page.py add peers runs/peers/peers.json --title "Peer agents on the arm"
    python tools/results_page.py            # rewrite docs/results.md and every block
    python tools/results_page.py --check    # exit 1 when any of them differs from the records

Exit status: 0 done (with --check: every page matches the records); 1 with --check, a page or a
block differs from the records (run the tool to rewrite it); 2 bad input: a usage error, or a
record (or a file given to add) that is not what this tool writes (torn, not UTF-8, nested too
deeply, not an object, a field missing or of the wrong kind), named in one line. CI can thus tell
a page merely out of date from a damaged record.

A record (docs/results/NAME.json) keeps what a benchmark wrote, the command that made it, the date
and the machine. Its kind says which benchmark: "seeds" (one group of robostrich-sweep's
sweep.json, or an earlier tools/benchmark_seeds.py seeds.json; tools/results_seeds.py renders it),
"dmc" (tools/benchmark_dmc.py's dmc.json), "layouts" (robostrich-layouts' layouts.json),
"design" (robostrich-design's design.json), "robustness" (robostrich-robustness's robustness.json),
"peers" (tools/benchmark_peers.py's peers.json) or "speed" (tools/benchmark_env.py, benchmark_a1.py or benchmark_learner.py with --json). Numbers are
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

import results_design
import results_dmc
import results_layouts
import results_peers
import results_robustness
import results_seeds
import results_speed
from robostrich_suite import atomic_files  # the project's one atomic writer
from robostrich_suite import parsing  # JSON read with a depth limit, errors naming the file

ROOT = pathlib.Path(__file__).resolve().parent.parent

RECORDS = ROOT / "docs" / "results"
PAGE = ROOT / "docs" / "results.md"
README = ROOT / "README.md"
FORMAT = 2
# A block "<!-- results: NAME (...) --> ... <!-- /results -->" in README.md or a page of docs/
# holds record NAME's table.
BLOCK_BEGIN = "<!-- results: {name} (tools/results_page.py writes this table) -->"
BLOCK_END = "<!-- /results -->"
README_RECORD = "main_job"  # the README's first table, which it must have

KINDS = {"seeds": results_seeds, "dmc": results_dmc, "layouts": results_layouts, "speed": results_speed,
         "design": results_design, "robustness": results_robustness, "peers": results_peers}
STALE, BAD_INPUT = 1, 2  # exit statuses besides 0 (module doc)
# A record's fields and their types; "note" and "order" may be left out.
RECORD_FIELDS = {"format": int, "name": str, "title": str, "kind": str, "command": str, "date": str,
                 "machine": str, "note": str, "order": int, "data": dict}
OPTIONAL_FIELDS = ("note", "order")
# What a record's data of the wrong shape raises in its kind's tables: a damaged record, not a bug here.
SHAPE_ERRORS = (KeyError, TypeError, AttributeError, IndexError, ValueError)


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
    layouts.json, robostrich-design's design.json or a speed benchmark's --json file; the command it records unless ``command`` says."""
    written = parsing.read_json(path)
    if not isinstance(written, dict):
        raise ValueError(f"{path}: a JSON {type(written).__name__}, not the object a benchmark writes")
    kind = kind_of(written)
    try:
        data, recorded = KINDS[kind].read(written, path, group) if kind == "seeds" else KINDS[kind].read(written, path)
    except SHAPE_ERRORS as error:
        raise _named(error, path, f"not the {kind} file this tool records") from None
    if group is not None and kind != "seeds":  # only a sweep has groups
        raise ValueError(f"--group {group}: {path} is not a sweep")
    command = command or recorded
    if not command:
        raise ValueError(f"{path} records no command: give --command")
    return check_renders({"format": FORMAT, "name": name, "title": title, "kind": kind, "command": command,
                          "date": date or datetime.date.today().isoformat(), "machine": machine(), "note": note,
                          "data": data}, path)


def _named(error: Exception, path, what: str) -> ValueError:
    """``error`` as a ValueError naming ``path`` (a message that already names it is kept)."""
    message = " ".join(str(error).split())
    if str(path) in message:
        return ValueError(message)
    return ValueError(f"{path}: {what} ({type(error).__name__}: {message})")


def read_record(path: pathlib.Path) -> dict:
    """The record in ``path``, checked: its fields, its kind, and that its tables render (a
    ValueError naming the file otherwise)."""
    record = parsing.read_json(path)
    if not isinstance(record, dict):
        raise ValueError(f"{path}: a JSON {type(record).__name__}, not a record (an object)")
    if record.get("format") != FORMAT:
        raise ValueError(f"{path} has record format {record.get('format')!r}, this tool reads {FORMAT}")
    for field, kind in RECORD_FIELDS.items():
        if field not in record and field in OPTIONAL_FIELDS:
            continue
        if field not in record:
            raise ValueError(f"{path}: the record has no {field!r}")
        if not isinstance(record[field], kind) or isinstance(record[field], bool):
            raise ValueError(f"{path}: the record's {field!r} is a {type(record[field]).__name__}, "
                             f"not a {kind.__name__}")
    if record["kind"] not in KINDS:
        raise ValueError(f"{path} has kind {record['kind']!r}; known: {', '.join(KINDS)}")
    return check_renders(record, path)


def check_renders(record: dict, path) -> dict:
    """``record`` once its page section and block render; a ValueError naming ``path`` (where its
    data came from) otherwise."""
    try:
        render_record(record)
        render_block(record)
    except SHAPE_ERRORS as error:
        raise _named(error, path, f"its data are not a {record['kind']} record's") from None
    return record


def read_records(directory: pathlib.Path = RECORDS) -> list:
    records, files_by_name = [], {}
    for path in sorted(directory.glob("*.json")):
        record = read_record(path)
        if record["name"] in files_by_name:
            raise ValueError(f"{path} and {files_by_name[record['name']]} both name record {record['name']!r}")
        files_by_name[record["name"]] = path
        records.append(record)
    return sorted(records, key=lambda r: (r.get("order", 100), r["name"]))


def read_page(path: pathlib.Path) -> str:
    """A page that may hold blocks, as text (a ValueError naming it if it is not UTF-8)."""
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError as error:
        raise ValueError(f"{path}: not a UTF-8 text file (byte {error.start} cannot be decoded)") from None


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
            "reached, and what did not help: [learning.md](learning.md), with its dated [log](log/learning.md).\n")
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


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False,
                                epilog=f"exit status: 0 done; {STALE} with --check, a page differs from the records; "
                                       f"{BAD_INPUT} bad input (a usage error, a damaged record or file)")
    sub = p.add_subparsers(dest="command")
    add = sub.add_parser("add", allow_abbrev=False, help="store what a benchmark wrote as a record in docs/results/")
    add.add_argument("name", help="the record's name (docs/results/NAME.json; a block names it)")
    add.add_argument("written", help="OUT/sweep.json of robostrich-sweep (or an earlier seeds.json), dmc.json of "
                     "tools/benchmark_dmc.py, layouts.json of robostrich-layouts, design.json of robostrich-design, or a "
                     "speed benchmark's --json file, or peers.json of tools/benchmark_peers.py")
    add.add_argument("--title", required=True)
    add.add_argument("--group", default=None, help="the sweep's group to record (default: its only one)")
    add.add_argument("--command", dest="run_command", default=None,
                     help="the command that produced it (default: the one the file records)")
    add.add_argument("--date", default=None, help="YYYY-MM-DD (default today)")
    add.add_argument("--note", default="", help="one paragraph shown under the title")
    add.add_argument("--order", type=int, default=100, help="position on the page (lower first)")
    p.add_argument("--check", action="store_true",
                   help=f"exit {STALE} when the page or a block differs from the records (and {BAD_INPUT} when a "
                        "record is damaged)")
    p.add_argument("--records", type=pathlib.Path, default=RECORDS, help=argparse.SUPPRESS)  # another folder (tests)
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    if args.command == "add":
        record = make_record(args.name, args.written, args.title, args.run_command, args.date, args.note,
                             args.group)
        record["order"] = args.order
        RECORDS.mkdir(parents=True, exist_ok=True)
        atomic_files.write_text(RECORDS / f"{args.name}.json", json.dumps(record, indent=1) + "\n")
        print(f"wrote {RECORDS / (args.name + '.json')}")
        return 0
    expected = expected_files(read_records(args.records), {path: read_page(path) for path in block_pages()})
    stale = [path for path, text in expected.items() if not path.exists() or read_page(path) != text]
    if args.check:
        for path in stale:
            print(f"{path.relative_to(ROOT)} differs from docs/results/*.json: run python tools/results_page.py",
                  file=sys.stderr)
        return STALE if stale else 0
    for path in stale:
        atomic_files.write_text(path, expected[path])
        print(f"wrote {path.relative_to(ROOT)}")
    return 0


def cli(argv=None) -> int:
    """``main`` with the exit statuses of the module doc: bad input is one line, status 2."""
    try:
        return main(argv)
    except (ValueError, OSError) as error:
        message = error.strerror + (f": {error.filename}" if error.filename else "") \
            if isinstance(error, OSError) and error.strerror else str(error)
        print(f"results_page: error: {' '.join(message.split())}", file=sys.stderr)
        return BAD_INPUT


if __name__ == "__main__":
    sys.exit(cli())
