"""Command-line flags generated from a configuration dataclass: one flag per field, its help and
default read from the dataclass (its ``HELP``), so the dataclass stays the one home of the defaults
and a command only exposes them; and the way back, from parsed flags to field values."""
import argparse
import dataclasses
import re
import sys
import typing


def config_flag(field_name: str) -> str:
    """The flag of one config field: ``--field-name``."""
    return "--" + field_name.replace("_", "-")


def _shown(value, field_name: str = "") -> str:
    """A default as --help shows it: a tuple as its flag takes it, an empty one by its keyword."""
    if isinstance(value, tuple) and not value:
        return _empty_keyword(field_name)
    return ",".join(map(str, value)) if isinstance(value, tuple) else str(value)


def _empty_keyword(field_name: str) -> str:
    """How the command line says an empty list: an empty lesson list means every lesson for hindsight
    goals (LessonSettings), so there it is `all`; elsewhere (no lesson, no fine input) `none`."""
    return "all" if field_name == "her_lessons" else "none"


def add_config_arguments(group, defaults, overrides: typing.Mapping[str, dict] = None):
    """One flag per field of ``defaults``' dataclass (``--field-name``), its default read from it:
    the dataclass is the one home of the training defaults, the CLI only exposes them.
    ``overrides`` ({where: {field: value}}) are defaults a command sets elsewhere (e.g. per
    domain), named in the help after the dataclass's own."""
    for field in dataclasses.fields(defaults):
        default = getattr(defaults, field.name)
        flag = config_flag(field.name)
        help_text = f"{type(defaults).HELP[field.name]} (default: {_shown(default, field.name)}"
        for domain, values in (overrides or {}).items():
            if field.name in values:
                help_text += f"; on {domain}: {_shown(values[field.name], field.name)}"
        help_text += ")"
        if isinstance(default, bool):
            group.add_argument(flag, dest=field.name, action=argparse.BooleanOptionalAction,
                               default=default, help=help_text)
        elif isinstance(default, tuple):
            item_type = typing.get_args(typing.get_type_hints(type(defaults))[field.name])[0]
            group.add_argument(flag, dest=field.name, type=_comma_list(item_type, field.name),
                               default=_shown(default, field.name), help=help_text)
        elif default is None:
            group.add_argument(flag, dest=field.name, type=float, default=None, help=help_text)
        else:
            group.add_argument(flag, dest=field.name, type=type(default), default=default, help=help_text)


def _comma_list(item_type, field_name: str = ""):
    """argparse type of a tuple field: the text as given once every item reads as ``item_type``,
    else a usage error naming the flag (int's own words would not). A lesson list's keyword
    (`all` for hindsight goals, `none` for the rest and for other lists) reads as the empty list it
    stands for."""

    def parse(text: str) -> str:
        keyword = _empty_keyword(field_name)
        if text.strip() == keyword:
            return ""
        if not text.strip() and field_name == "her_lessons":  # elsewhere empty means none, as it says
            raise argparse.ArgumentTypeError(f"name the lessons, separated by commas, or {keyword}")
        for item in filter(None, (part.strip() for part in text.split(","))):
            try:
                item_type(item)
            except ValueError:
                kind = "whole numbers" if item_type is int else f"{item_type.__name__} values"
                raise argparse.ArgumentTypeError(f"expected {kind} separated by commas, got {text!r} "
                                                 f"({item!r} is not one)") from None
        return text
    return parse


def parsed_values(args, cls) -> dict:
    """Field values of dataclass ``cls`` from parsed flags: a tuple field's text ("64,64",
    "lesson1,lesson2") split into its items' type."""
    values = {f.name: getattr(args, f.name) for f in dataclasses.fields(cls)}
    hints = typing.get_type_hints(cls)
    for field in dataclasses.fields(cls):
        if isinstance(field.default, tuple):
            item_type = typing.get_args(hints[field.name])[0]
            values[field.name] = tuple(item_type(item.strip()) for item in str(values[field.name]).split(",")
                                       if item.strip())
    return values


def with_flags(message: str, classes) -> str:
    """``message`` with every field name of the dataclasses ``classes`` replaced by its flag,
    e.g. learning_rate -> --learning-rate (a config names its fields; the user typed flags)."""
    flags = {f.name: config_flag(f.name) for cls in classes for f in dataclasses.fields(cls)}
    return re.sub(r"\b(" + "|".join(sorted(flags, key=len, reverse=True)) + r")\b",
                  lambda m: flags[m.group(1)], message)


def explicit_fields(argv, cls) -> set:
    """Fields of dataclass ``cls`` named on the command line ``argv`` (sys.argv's when None), so that
    a preset of the command's does not override them."""
    argv = sys.argv[1:] if argv is None else list(argv)
    named = set()
    for field in dataclasses.fields(cls):
        flag = config_flag(field.name)
        for token in argv:
            option = token.split("=", 1)[0]
            if option in (flag, "--no-" + flag[2:]):
                named.add(field.name)
    return named
