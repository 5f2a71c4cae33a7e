"""An arm described in a file: every field of :class:`~robostrich_suite.model.arm.ArmSpec` and its
routing, in TOML, so that a researcher's own tendon arm needs no Python.

The schema (``robostrich_suite/data/arms/robostrich.toml`` is Table 1's arm written by :func:`text`)::

    name = "robostrich"              # the arm's name (its MJCF files are named after it)
    [arm]                            # ArmSpec's fields in SI units (``UNITS``), sequences head first;
    joint_names = ["atlas", ...]     # a field left out keeps Table 1's value
    ...
    [routing]
    layout = "ventral_slips"         # a built-in routing, or
    # file = "my_routing.toml"       # a layout file (docs/layouts.md), relative to this file

A file that cannot be an arm is refused with one line naming the file, the field and the rule it
breaks (``ArmFileError``, a ValueError: the commands' one-line error, exit status 2).
"""
from __future__ import annotations

import dataclasses
import json
import pathlib

from robostrich_suite import parsing
from robostrich_suite.model import arm as arm_lib
from robostrich_suite.model import layouts

SHIPPED_DIR = pathlib.Path(__file__).resolve().parents[1] / "data" / "arms"
# The unit of each ArmSpec field, as the written file's comments give it.
UNITS = {"joint_names": "head first, base last", "dorsal_limits_deg": "deg, magnitudes in [0, 180)",
         "ventral_limits_deg": "deg, magnitudes in [0, 180)", "link_lengths": "m, for joint_names[1:]",
         "masses": "kg, head first", "head_length": "m", "head_site_fraction": "of the head's length",
         "link_radius": "m", "hole_offset": "m", "hole_fraction": "of a link, from its caudal joint",
         "anchor_depth": "m", "joint_stiffness": "N m / rad", "joint_damping": "N m s / rad",
         "joint_armature": "kg m^2", "limit_solref": "MuJoCo solref", "limit_solimp": "MuJoCo solimp",
         "tendon_kp": "N / m", "tendon_kv": "N s / m", "tendon_max_force": "N"}
ROUTING_KEYS = ("layout", "file")


class ArmFileError(ValueError):
    """An arm file that cannot be read as an arm (the message names the file and the field)."""


@dataclasses.dataclass(frozen=True)
class ArmFile:
    """What an arm file describes: its name, the arm, its routing and where the routing came from."""
    name: str
    spec: arm_lib.ArmSpec
    layout: arm_lib.TendonLayout
    routing: str  # the built-in layout's name, or the layout file's path


def read(path) -> ArmFile:
    """The arm of the file ``path``; ArmFileError naming the field and the rule it breaks."""
    path = pathlib.Path(path)
    data = _load(path)
    fail = _failer(path)
    unknown = sorted(set(data) - {"name", "arm", "routing"})
    if unknown:
        fail(unknown[0], "unknown key; an arm file has name, [arm] and [routing]")
    name = data.get("name", path.stem)
    if not isinstance(name, str) or not name.isidentifier():
        fail("name", f"must be a name of letters, digits and underscores, got {name!r}")
    spec = _spec(data.get("arm", {}), fail)
    layout, routing = _routing(data.get("routing", {"layout": layouts.DEFAULT}), spec, path, fail)
    return ArmFile(name, spec, layout, routing)


def _load(path: pathlib.Path) -> dict:
    """The file's TOML (parsing.read_toml: a FIFO or a device is refused at once, not read); a
    missing file is the OSError naming it."""
    try:
        return parsing.read_toml(path)
    except ValueError as error:  # not a regular file, too large, not UTF-8 or not TOML: the message names the file
        raise ArmFileError(str(error)) from None


def _failer(path: pathlib.Path):
    def fail(field: str, rule: str):
        raise ArmFileError(f"{path}: {field}: {rule}")
    return fail


def _spec(table, fail) -> arm_lib.ArmSpec:
    """ArmSpec from the [arm] table over Table 1's; every field checked for its type, then the arm
    checked whole (ArmSpec.validate names the joint or field)."""
    if not isinstance(table, dict):
        fail("arm", "must be a table ([arm])")
    table1 = arm_lib.ArmSpec.from_table1()
    fields = {f.name: getattr(table1, f.name) for f in dataclasses.fields(arm_lib.ArmSpec)}
    values = {}
    for key, value in table.items():
        if key not in fields:
            fail(f"arm.{key}", f"unknown field; the fields are {list(fields)}")
        values[key] = _typed(f"arm.{key}", value, fields[key], fail)
    spec = dataclasses.replace(table1, **values)
    try:
        spec.validate()
    except ValueError as error:
        fail("arm", str(error))
    return spec


def _typed(field: str, value, like, fail):
    """``value`` as the type of Table 1's ``like`` (a number, a string, or a sequence of either)."""
    def number(x):
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            fail(field, f"must be a number, got {x!r}")
        return float(x)
    if isinstance(like, tuple):
        if not isinstance(value, list):
            fail(field, f"must be a list, got {value!r}")
        if like and isinstance(like[0], str):
            if not all(isinstance(x, str) for x in value):
                fail(field, "must be a list of names")
            return tuple(value)
        return tuple(number(x) for x in value)
    return number(value)


def _routing(table, spec, path: pathlib.Path, fail):
    """(layout, where it came from) from the [routing] table, checked to fit the arm's links."""
    if not isinstance(table, dict) or len(table) != 1 or next(iter(table)) not in ROUTING_KEYS:
        fail("routing", 'must be one of layout = "NAME" (a built-in routing) or file = "PATH" (a layout file)')
    key, value = next(iter(table.items()))
    if not isinstance(value, str):
        fail(f"routing.{key}", f"must be a string, got {value!r}")
    try:
        if key == "layout":
            return layouts.build(value, spec), value
        source = (path.parent / value).resolve()
        return layouts.read_file(source, spec)[1], str(source)
    except (ValueError, KeyError) as error:  # a routing that names links the arm does not have
        fail(f"routing.{key}", f"{value!r} does not fit this arm: {error}")
    except OSError as error:
        fail(f"routing.{key}", f"cannot read {value!r}: {error.strerror or error}")


def text(name: str, spec: arm_lib.ArmSpec, routing: str = layouts.DEFAULT) -> str:
    """The arm file of ``spec`` (every field, with its unit) and a built-in ``routing``."""
    lines = [f"# The arm {name!r} for robostrich_suite (robostrich_suite/model/arm_file.py): SI units,",
             "# sequences head first. robostrich-export-xml --arm FILE writes its MJCF.",
             f"name = {json.dumps(name)}", "", "[arm]"]
    for field in dataclasses.fields(arm_lib.ArmSpec):
        value = getattr(spec, field.name)
        shown = json.dumps(list(value) if isinstance(value, tuple) else value)
        lines.append(f"{field.name} = {shown}  # {UNITS[field.name]}")
    return "\n".join(lines + ["", "[routing]", f"layout = {json.dumps(routing)}", ""])
