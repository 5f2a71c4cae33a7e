"""Every flag of every installed command says in one line what it does (`--help`), and the
training flags generated from the agent's settings carry their fields' help."""
import dataclasses
import re

from agents.curriculum import LessonSettings
from agents.robostrich.commands import COMMANDS
from agents.sac.config import SACConfig
from conftest import finish, start

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
    processes = {name: start(name, "--help") for name in COMMANDS}
    missing = {}
    for name, process in processes.items():
        result = finish(process, timeout=120)
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
