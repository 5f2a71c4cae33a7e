"""Every flag of every installed command says in one line what it does (`--help`), and the
training flags generated from the agent's settings carry their fields' help."""
import dataclasses
import re

from agents.curriculum import LessonSettings
from agents.sac.config import SACConfig
from robostrich_commands import COMMANDS
import conftest
from conftest import run_in_one_process

FLAG = re.compile(r"^  (-\w, )?(--[\w-]+)(.*)$")
ONLY_DEFAULT = re.compile(r"^\(default: [^)]*\)$")


def flags_without_help(help_text: str) -> list:
    """Flags whose description in `help_text` is empty or only '(default: X)'."""
    lines, missing = help_text.splitlines(), []
    for i, line in enumerate(lines):
        match = FLAG.match(line)
        if not match or match.group(2) == "--help":
            continue
        parts = re.split(r"\s{2,}", line.strip(), maxsplit=1)
        text = parts[1] if len(parts) > 1 else ""
        k = i + 1
        while k < len(lines) and lines[k].startswith(" " * 10) and not FLAG.match(lines[k]):
            text += " " + lines[k].strip()
            k += 1
        if not text.strip() or ONLY_DEFAULT.match(text.strip()):
            missing.append(match.group(2))
    return missing


def test_the_help_parser_finds_flags_without_text():
    text = "options:\n  --a A       does a\n  --b B\n  --c C       (default: 3)\n  --long-name LONG_NAME\n" \
           "                        wrapped help\n  --d\n"
    assert flags_without_help(text) == ["--b", "--c", "--d"]


def test_every_flag_of_every_command_is_explained():
    missing = {}
    for name, result in run_in_one_process({name: (name, ["--help"]) for name in COMMANDS}).items():
        assert result.returncode == 0, (name, result.stderr)
        assert "\n  --" in result.stdout, name
        if flags_without_help(result.stdout):
            missing[name] = flags_without_help(result.stdout)
    assert not missing


def test_every_agent_setting_has_its_one_line_help():
    for cls in (SACConfig, LessonSettings):
        names = {f.name for f in dataclasses.fields(cls)}
        assert set(cls.HELP) == names, cls.__name__
        assert all(text and "\n" not in text and len(text) <= 110 for text in cls.HELP.values())


SHOW_DEFAULTS = r'''
import argparse, importlib, json
from robostrich_commands import COMMANDS

class Caught(BaseException):
    def __init__(self, parser):
        self.parser = parser

def catch(self, *args, **kwargs):
    raise Caught(self)

argparse.ArgumentParser.parse_args = argparse.ArgumentParser.parse_known_args = catch
found = {}
for prog, target in COMMANDS.items():
    module, function = target.split(":")
    try:
        getattr(importlib.import_module(module), function)(["--help"])
    except Caught as caught:
        formatter = caught.parser._get_formatter()
        found[prog] = {action.option_strings[-1]: formatter._expand_help(action) for action in caught.parser._actions
                       if action.option_strings and action.help != argparse.SUPPRESS
                       and action.default not in (None, argparse.SUPPRESS)
                       and (action.nargs != 0 or isinstance(action, argparse.BooleanOptionalAction))}
print(json.dumps(found))
'''


def test_every_flag_with_a_default_shows_it_in_words():
    """A flag that takes a value (or --x/--no-x) and has a default says it; an empty default is
    said in a word ('none', 'all'), never '(default: )'. Read from each command's own parser."""
    import json
    import subprocess
    import sys
    result = subprocess.run([sys.executable, "-c", SHOW_DEFAULTS], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    helps = json.loads(result.stdout.strip().splitlines()[-1])
    assert set(helps) == set(COMMANDS)
    silent = {f"{prog} {flag}": text for prog, flags in helps.items() for flag, text in flags.items()
              if "default" not in text or re.search(r"default: *[;)]", text)}
    assert not silent, silent


def test_the_stored_help_of_every_command_is_what_its_parser_prints():
    """The launcher's --help text (robostrich_suite/data/help/) is written by tools/command_help.py
    from each command's own parser: one source, checked here, so a changed flag cannot leave it stale."""
    import subprocess
    import sys
    result = subprocess.run([sys.executable, "tools/command_help.py", "--check"], capture_output=True, text=True,
                            timeout=300, cwd=conftest.ROOT)
    assert result.returncode == 0, result.stderr[-3000:]


HELP_WITHOUT_IMPORTS = r'''
import contextlib, io, json, sys
import robostrich_commands
shown = {}
for prog in robostrich_commands.COMMANDS:
    sys.argv = [prog, "--help"]
    with contextlib.redirect_stdout(io.StringIO()) as out:
        status = robostrich_commands.launch(prog)
    shown[prog] = [status, out.getvalue().startswith(f"usage: {prog} ")]
print(json.dumps({"shown": shown, "heavy": sorted(m for m in ("jax", "mujoco", "dm_control", "matplotlib")
                                                  if m in sys.modules)}))
'''


def test_help_answers_before_any_heavy_import():
    """`robostrich-X --help` prints its usage and exits 0 having imported neither JAX nor MuJoCo
    (seconds of imports before: 7-9 s on two cores), for every command, and as an installed script."""
    import json
    import subprocess
    import sys
    result = subprocess.run([sys.executable, "-c", HELP_WITHOUT_IMPORTS], capture_output=True, text=True, timeout=120,
                            cwd=conftest.ROOT)
    assert result.returncode == 0, result.stderr[-3000:]
    report = json.loads(result.stdout)
    assert report["heavy"] == [] and report["shown"] == {prog: [0, True] for prog in COMMANDS}, report
    installed = subprocess.run([conftest.console_script("robostrich-train"), "--help"], capture_output=True, text=True,
                               timeout=120)
    assert installed.returncode == 0 and installed.stdout.startswith("usage: robostrich-train "), installed.stderr


def test_one_name_per_idea_across_commands():
    """Every command turns off its progress bar with --no-progress and its .rrd recordings with
    --no-rerun (the older --quiet, --no-rrd and --no-recording stay as aliases)."""
    import robostrich_commands
    named = {}
    for prog in COMMANDS:
        lines = open(robostrich_commands.help_path(prog), encoding="utf-8").read().splitlines()
        for i, line in enumerate(lines):
            match = FLAG.match(line)
            if not match or not match.group(2).startswith("--no-"):
                continue
            text, k = line, i + 1
            while k < len(lines) and lines[k].startswith(" " * 10) and not FLAG.match(lines[k]):
                text, k = text + " " + lines[k].strip(), k + 1
            for idea, name in (("progress bar", "--no-progress"), (".rrd", "--no-rerun")):
                if idea in text:
                    named.setdefault(idea, set()).add(match.group(2))
    assert named == {"progress bar": {"--no-progress"}, ".rrd": {"--no-rerun"}}, named


def stored_help(prog: str) -> str:
    import robostrich_commands
    return " ".join(open(robostrich_commands.help_path(prog), encoding="utf-8").read().split())


def test_help_defines_its_terms_instead_of_pointing_at_the_source():
    """What a flag or a word means is in the help itself: no "(module doc)", no file to read for a
    flag's meaning, no Python tuple as a default, no constant's name where its value belongs."""
    from agents.robostrich.robustness import command as robustness
    from robostrich_suite.tasks import perturbations
    texts = {prog: stored_help(prog) for prog in COMMANDS}
    for prog, text in texts.items():
        assert "module doc" not in text and "(default: (" not in text, prog
        assert not re.search(r"\b[A-Z][A-Z0-9]+(_[A-Z0-9]+)*_AT_1\b", text), prog
    robust = texts["robostrich-robustness"]
    assert "(default: " + ",".join(f"{s:g}" for s in robustness.DEFAULT_SCALES) + ")" in robust
    assert all(f"* {family}" in robust for family in perturbations.FAMILIES), robust
    assert "passage" in texts["robostrich-design"] and "before anything touches" in texts["robostrich-design"]
    assert "P_d, the head's desired distance ahead of the trunk centre" in texts["robostrich-stabilize"]
    assert "blue region of Fig. 6 (where the links can put the head level" in texts["robostrich-layouts"]



def test_the_layout_file_example_in_help_is_a_file_the_commands_read(tmp_path):
    from robostrich_suite.model import layouts
    example = stored_help("robostrich-layouts").split("for example ", 1)[1]
    (tmp_path / "example.json").write_text(example)
    name, layout = layouts.read_file(tmp_path / "example.json")
    assert name == "two_dorsal" and [t.name for t in layout.tendons] == ["dorsal", "ventral_skip"]
