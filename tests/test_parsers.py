"""No command takes an abbreviated flag: `--learning-rat` must not quietly set --learning-rate (and
would change meaning the day a flag --learning-rate-decay is added)."""
import ast
import pathlib

import pytest

from robostrich_suite import cli

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOURCES = [p for folder in ("agents", "robostrich_suite", "tools") for p in sorted((ROOT / folder).rglob("*.py"))]


def test_the_commands_parser_refuses_an_abbreviated_flag(capsys):
    parser = cli.Parser(prog="robostrich-x")
    parser.add_argument("--learning-rate", type=float)
    with pytest.raises(SystemExit) as exit_info:
        parser.parse_args(["--learning-rat", "1e-3"])
    assert exit_info.value.code == cli.USER_ERROR
    assert "unrecognized arguments: --learning-rat" in capsys.readouterr().err
    assert parser.parse_args(["--learning-rate", "1e-3"]).learning_rate == 1e-3


def test_every_plain_argparse_parser_refuses_abbreviations():
    """argparse's own parsers (the tools', a subcommand's) must say allow_abbrev=False themselves."""
    missing = []
    for path in SOURCES:
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr in ("ArgumentParser", "add_parser")):
                abbrev = [k for k in node.keywords if k.arg == "allow_abbrev"]
                if not (abbrev and isinstance(abbrev[0].value, ast.Constant) and abbrev[0].value.value is False):
                    missing.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert not missing, missing
