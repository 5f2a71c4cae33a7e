"""The installed commands' entry points, light enough to catch Ctrl-C from the first instant.

A console script imports its module before anything can handle an interrupt; ours pull in MuJoCo,
JAX and matplotlib, which takes seconds. Each entry here imports its command's module with Ctrl-C
noted, so Ctrl-C while that happens ends the command as Ctrl-C anywhere else does: one line
``PROG: interrupted`` and exit status 130 (robostrich_suite/cli.py), not Python's traceback; SIGTERM
likewise (``PROG: terminated``, 143).
A module of its own beside both packages, not inside either: importing a package runs its
``__init__`` (robostrich_suite's loads dm_control) before Ctrl-C could be noted, and the suite's
commands must not start through the agent. It imports only importlib, signal and sys, and names each
command's module as text (tests/test_hostile_input.py and tests/test_layers.py check).

``--help`` answers from the text its parser printed when ``python tools/command_help.py`` last
wrote ``robostrich_suite/data/help/`` (tests/test_command_help.py checks that it is current), so
help comes at once instead of after seconds of imports.
"""
import importlib
import os
import signal
import sys

INTERRUPTED = 130  # as robostrich_suite.cli.INTERRUPTED and TERMINATED, which this module must not import
TERMINATED = 143

COMMANDS = {
    "robostrich-train": "agents.robostrich.train.command:cli",
    "robostrich-evaluate": "agents.robostrich.evaluate.command:cli",
    "robostrich-layouts": "agents.robostrich.layouts:cli",
    "robostrich-stabilize": "agents.robostrich.applications.stabilize:cli",
    "robostrich-gap": "agents.robostrich.applications.gap:cli",
    "robostrich-play": "agents.robostrich.applications.play:cli",
    "robostrich-walk": "robostrich_suite.studies.walk:cli",
    "robostrich-export-xml": "robostrich_suite.export_xml:cli",
    "robostrich-movement": "robostrich_suite.studies.movement:cli",
    "robostrich-workspace": "robostrich_suite.studies.workspace:cli",
    "robostrich-targets": "robostrich_suite.studies.targets:cli",
    "robostrich-gait": "robostrich_suite.studies.gait:cli",
    "robostrich-sweep": "agents.robostrich.sweep.command:cli",
    "robostrich-design": "robostrich_suite.studies.design:cli",
    "robostrich-robustness": "agents.robostrich.robustness.command:cli",
}


HELP_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "robostrich_suite", "data", "help")


def help_path(prog: str) -> str:
    return os.path.join(HELP_DIR, f"{prog}.txt")


def _asks_for_help(argv) -> bool:
    """-h or --help before any '--': argparse answers it wherever it stands."""
    for arg in argv:
        if arg == "--":
            return False
        if arg in ("-h", "--help"):
            return True
    return False


def launch(prog: str) -> int:
    """Import `prog`'s module and run its cli(); ``--help`` from its stored text, with no import.
    Ctrl-C during the import is noted, not raised (an interrupt raised inside a native module's
    import can crash the interpreter, and JAX's garbage-collection callback swallows one): the
    command ends as interrupted once the import is done, before it starts any work."""
    if _asks_for_help(sys.argv[1:]):
        try:
            with open(help_path(prog), encoding="utf-8") as stored:
                sys.stdout.write(stored.read())
            return 0
        except OSError:  # not written for this command: its parser prints it, after the imports
            pass
    module, function = COMMANDS[prog].split(":")
    interrupted = []
    previous = {signum: signal.signal(signum, lambda signum, frame: interrupted.append(signum))
                for signum in (signal.SIGINT, signal.SIGTERM)}
    shown = _show_loading(prog)
    try:
        cli = getattr(importlib.import_module(module), function)
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        if shown:
            sys.stderr.write(CLEAR_LINE)
            sys.stderr.flush()
    if interrupted:
        terminated = interrupted[-1] == signal.SIGTERM
        print(f"{prog}: {'terminated' if terminated else 'interrupted'}", file=sys.stderr)
        return TERMINATED if terminated else INTERRUPTED
    try:
        return cli()
    except KeyboardInterrupt:  # in the instant between the command's end and its own handling
        _ignore_stop_signals()
        print(f"{prog}: interrupted", file=sys.stderr)
        return INTERRUPTED
    finally:
        _ignore_stop_signals()


CLEAR_LINE = "\r\033[K"  # back to the line's start, and erase it


def _show_loading(prog: str) -> bool:
    """At a terminal, a note on stderr while the command's libraries load (seconds, before the
    command can print anything), erased once they have; nothing where stderr is a file or pipe."""
    try:
        if not sys.stderr.isatty():
            return False
        sys.stderr.write(f"{prog}: loading its libraries...")
        sys.stderr.flush()
        return True
    except (AttributeError, OSError, ValueError):  # no stderr, or a closed one
        return False


def _ignore_stop_signals() -> None:
    """The command is done and its status set: a stop while the interpreter shuts down (JAX, Rerun,
    a fraction of a second) changes nothing. Python puts back the default handlers of signals it
    handles as it exits, and the default would end the process by the signal, with no line."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, signal.SIG_IGN)


def _entry(prog: str):
    def entry() -> int:
        return launch(prog)
    entry.__name__ = entry.__qualname__ = prog.removeprefix("robostrich-").replace("-", "_")
    entry.__doc__ = f"Console script `{prog}` ({COMMANDS[prog]})."
    return entry


train = _entry("robostrich-train")
evaluate = _entry("robostrich-evaluate")
layouts = _entry("robostrich-layouts")
stabilize = _entry("robostrich-stabilize")
gap = _entry("robostrich-gap")
play = _entry("robostrich-play")
walk = _entry("robostrich-walk")
export_xml = _entry("robostrich-export-xml")
movement = _entry("robostrich-movement")
workspace = _entry("robostrich-workspace")
targets = _entry("robostrich-targets")
gait = _entry("robostrich-gait")
sweep = _entry("robostrich-sweep")
design = _entry("robostrich-design")
robustness = _entry("robostrich-robustness")
