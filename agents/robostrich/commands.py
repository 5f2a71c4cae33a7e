"""The installed commands' entry points, light enough to catch Ctrl-C from the first instant.

A console script imports its module before anything can handle an interrupt; ours pull in MuJoCo,
JAX and matplotlib, which takes seconds. Each entry here imports its command's module inside a
guard, so Ctrl-C while that happens ends the command as Ctrl-C anywhere else does: one line
``PROG: interrupted`` and exit status 130 (robostrich_suite/cli.py), not Python's traceback.
Importing this module loads nothing heavy (tests/test_layers.py checks).
"""
import importlib
import sys

INTERRUPTED = 130  # as robostrich_suite.cli.INTERRUPTED, which this module must not import

COMMANDS = {
    "robostrich-train": "agents.robostrich.training:cli",
    "robostrich-evaluate": "agents.robostrich.evaluation:cli",
    "robostrich-layouts": "agents.robostrich.layouts:cli",
    "robostrich-stabilize": "agents.robostrich.application_commands:stabilize_cli",
    "robostrich-gap": "agents.robostrich.application_commands:gap_cli",
    "robostrich-play": "agents.robostrich.play:cli",
    "robostrich-walk": "robostrich_suite.studies.walk:cli",
    "robostrich-export-xml": "robostrich_suite.xml_export:cli",
    "robostrich-movement": "robostrich_suite.studies.movement:cli",
    "robostrich-workspace": "robostrich_suite.studies.workspace:cli",
    "robostrich-targets": "robostrich_suite.studies.target_generation:cli",
    "robostrich-gait": "robostrich_suite.studies.gait_generation:cli",
}


def launch(prog: str) -> int:
    """Import `prog`'s module and run its cli(); Ctrl-C during the import is an interruption."""
    module, function = COMMANDS[prog].split(":")
    try:
        cli = getattr(importlib.import_module(module), function)
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return INTERRUPTED
    return cli()


def _entry(prog: str):
    def entry() -> int:
        return launch(prog)
    entry.__name__ = entry.__qualname__ = prog.removeprefix("robostrich-").replace("-", "_")
    entry.__doc__ = f"Console script `{prog}` ({COMMANDS[prog]})."
    return entry


train, evaluate, layouts, stabilize, gap, play, walk, export_xml, movement, workspace, targets, gait = (
    _entry(prog) for prog in COMMANDS)
