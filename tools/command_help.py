"""Write every installed command's --help text into robostrich_suite/data/help/, which the
launcher (robostrich_commands.py) prints without importing the command's module.

    python tools/command_help.py           # write the files
    python tools/command_help.py --check   # exit 1 if any file differs from its parser's help

Each command's own parser prints the text (its cli(["--help"])), at a width of WIDTH columns.
"""
import contextlib
import importlib
import io
import os
import pathlib
import sys

import robostrich_commands

WIDTH = 100


def rendered(prog: str) -> str:
    """What ``prog --help`` prints from its parser."""
    module, function = robostrich_commands.COMMANDS[prog].split(":")
    os.environ["COLUMNS"] = str(WIDTH)
    argv0, sys.argv[0] = sys.argv[0], prog  # a parser without its own prog names itself after argv[0]
    printed = io.StringIO()
    try:
        with contextlib.redirect_stdout(printed):
            getattr(importlib.import_module(module), function)(["--help"])
    except SystemExit as done:
        if done.code not in (0, None):
            raise RuntimeError(f"{prog} --help exited {done.code}") from None
    finally:
        sys.argv[0] = argv0
    return printed.getvalue()


def main(argv=None) -> int:
    check = "--check" in (sys.argv[1:] if argv is None else argv)
    stale = []
    for prog in robostrich_commands.COMMANDS:
        text, path = rendered(prog), pathlib.Path(robostrich_commands.help_path(prog))
        if check:
            if not path.exists() or path.read_text(encoding="utf-8") != text:
                stale.append(prog)
        else:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text, encoding="utf-8")
    if stale:
        print(f"stale --help text of {', '.join(stale)}: run python tools/command_help.py", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
