"""Named tendon layouts, and layouts read from a small declarative file.

The paper's text does not give its routing (Fig. 1B): :data:`DEFAULT` is the reconstruction
its own tests choose among the candidates that keep its tendons (:func:`fig1b_candidates`;
docs/layouts.md).  It left "the comparison of various tendon configurations" open;
``robostrich-layouts`` (:mod:`robostrich_suite.studies.layout_compare`) compares the ones
here.  Every built-in uses the Table 1 links, at most
:data:`MAX_TENDONS` tendons and the generator's servos (ranges from the joint
limits, the same force limit), so only the routing differs.

A user tries another routing without Python in JSON or TOML; each tendon has a
``name``, a ``side`` (dorsal or ventral) and either ``links`` (the holes it runs
through, caudal to cranial; ``on_base`` false ties it at the first one instead of
an anchor on the base) or ``from``/``to`` (every link between, as
``TendonSpec.spanning``), and optionally a ``hole_offset``: its holes' distance from the
joint axis in metres, its moment arm (default: the arm's 0.015; bounded by
``arm.HOLE_OFFSET_RANGE``)::

    name = "two_dorsal"
    [[tendons]]
    name = "dorsal"
    side = "dorsal"
    from = "c18"
    to = "atlas"
    [[tendons]]
    name = "ventral_skip"
    side = "ventral"
    links = ["c18", "c12", "c6", "c3"]
    hole_offset = 0.02

A malformed file raises :class:`LayoutFileError` (a ``ValueError``) naming the
file, the tendon and what is wrong; a well-formed file describing a bad layout
gets ``TendonLayout.validate``'s message, prefixed with the file.
"""
from __future__ import annotations

import dataclasses
import json
import math
import pathlib
from typing import Callable

from robostrich_suite.model import arm as arm_lib
from robostrich_suite import input_files, targets

MAX_TENDONS = 9  # the paper's 9 servos: the built-ins compare at the same actuation budget
# A layout file may have more (robostrich-design's searches beyond the paper's family write them,
# up to 4 dorsal + 16 ventral); robostrich-layouts' table gives each case's count.
MAX_FILE_TENDONS = 20
DATA_DIR = pathlib.Path(__file__).resolve().parents[1] / "data"


def example_file() -> str:
    """The module doc's example layout file as one line of JSON (what --help shows)."""
    import tomllib
    block = __doc__.split("::", 1)[1].split("\n\n")[1]
    return json.dumps(tomllib.loads("\n".join(line.strip() for line in block.splitlines())))

# Antagonist pairs: the neck cut into four stretches, each with a dorsal and a ventral
# slip between the same two links, plus the paper's dorsal tendon to the head.  The
# passive neck is an inverted pendulum; a stretch pulled from both sides holds its bend
# whichever way gravity turns it.  These cuts held the most of the blue region of the
# cuts tried (docs/layouts.md).
ANTAGONIST_CUTS = ("c18", "c13", "c9", "c5", "atlas")


MAX_FILE_BYTES = 10_000_000  # a layout file is a few kB; anything this big is not one


class LayoutFileError(ValueError):
    """A layout file that cannot be read as a layout; the message names file and item."""


def ventral_from_base(spec: arm_lib.ArmSpec) -> arm_lib.TendonLayout:
    """A dorsal tendon to the head and 8 ventral tendons anchored on the base, inserting at
    every second vertebra C16 ... C2 (the project's first guess at the paper's Fig. 1B)."""
    return arm_lib.TendonLayout.ventral_from_base(spec)


def ventral_slips(spec: arm_lib.ArmSpec) -> arm_lib.TendonLayout:
    """The paper's Fig. 1B as we reconstruct it (the default): the dorsal tendon to the
    head and 8 ventral slips at the same insertions, each tied 4 joints caudal of its
    insertion, like the ostrich's overlapping longus colli slips."""
    return arm_lib.TendonLayout.ventral_slips(spec)


def _slips_of_span(span: int):
    def factory(spec: arm_lib.ArmSpec) -> arm_lib.TendonLayout:
        return arm_lib.TendonLayout.ventral_slips(spec, span=span)
    factory.__name__ = f"ventral_slips_{span}"
    factory.__doc__ = (f"As ventral_slips, each slip tied {span} joints caudal of its insertion "
                       "(another candidate reconstruction of Fig. 1B).")
    return factory


def second_dorsal(spec: arm_lib.ArmSpec) -> arm_lib.TendonLayout:
    """A second dorsal tendon from the base to mid-neck (C9) that holds the caudal neck
    up against gravity; the most caudal ventral tendon (C16) gives way to it."""
    dorsal = arm_lib.TendonSpec.spanning("dorsal", "dorsal", spec.head_name, spec)
    mid = arm_lib.TendonSpec.spanning("dorsal_c9", "dorsal", "c9", spec)
    ventral = [arm_lib.TendonSpec.spanning(f"ventral_{link}", "ventral", link, spec)
               for link in arm_lib.TendonLayout.ROBOSTRICH_VENTRAL_INSERTIONS[1:]]
    return arm_lib.TendonLayout((dorsal, mid, *ventral))


def cranial_every(spec: arm_lib.ArmSpec) -> arm_lib.TendonLayout:
    """Ventral tendons from the base inserting on every vertebra of the cranial half
    (C9 ... C2), where Table 1 allows the largest bends."""
    dorsal = arm_lib.TendonSpec.spanning("dorsal", "dorsal", spec.head_name, spec)
    ventral = [arm_lib.TendonSpec.spanning(f"ventral_c{n}", "ventral", f"c{n}", spec)
               for n in range(9, 1, -1)]
    return arm_lib.TendonLayout((dorsal, *ventral))


def antagonist_pairs(spec: arm_lib.ArmSpec) -> arm_lib.TendonLayout:
    """The paper's dorsal tendon plus a dorsal and a ventral slip on each of four
    stretches of the neck (cut at :data:`ANTAGONIST_CUTS`)."""
    tendons = [arm_lib.TendonSpec.spanning("dorsal", "dorsal", spec.head_name, spec)]
    for origin, insertion in zip(ANTAGONIST_CUTS[:-1], ANTAGONIST_CUTS[1:]):
        for side in arm_lib.SIDES:
            tendons.append(arm_lib.TendonSpec.spanning(f"{side}_{origin}_{insertion}", side,
                                                       insertion, spec, origin=origin))
    return arm_lib.TendonLayout(tuple(tendons))


@dataclasses.dataclass(frozen=True)
class BuiltIn:
    factory: Callable[[arm_lib.ArmSpec], arm_lib.TendonLayout]

    @property
    def description(self) -> str:
        return " ".join(self.factory.__doc__.split())


# Spans of the other candidate reconstructions of Fig. 1B (docs/layouts.md).
CANDIDATE_SLIP_SPANS = (2, 3, 6)
BUILT_IN = {f.__name__: BuiltIn(f) for f in (ventral_slips, *map(_slips_of_span, CANDIDATE_SLIP_SPANS),
                                             ventral_from_base, second_dorsal, cranial_every,
                                             antagonist_pairs)}
DEFAULT = "ventral_slips"  # the tasks' layout: arm_lib.TendonLayout.robostrich
# Names a layout had before, with its name now: a checkpoint or command line naming one gets told.
RENAMED = {"paper": "ventral_from_base"}


def follows_fig1b(layout: arm_lib.TendonLayout, spec: arm_lib.ArmSpec | None = None) -> bool:
    """True for a candidate reconstruction of the paper's Fig. 1B: one dorsal tendon to the head
    and eight ventral tendons at the paper's insertion levels (C16, C14, ..., C2), however
    they are routed caudally."""
    spec = spec or arm_lib.ArmSpec.from_table1()
    dorsal = [t for t in layout.tendons if t.side == "dorsal"]
    ventral = sorted(t.insertion for t in layout.tendons if t.side == "ventral")
    return (len(dorsal) == 1 and dorsal[0].insertion == spec.head_name
            and ventral == sorted(arm_lib.TendonLayout.ROBOSTRICH_VENTRAL_INSERTIONS))


def fig1b_candidates() -> list[str]:
    """The built-in layouts that :func:`follows_fig1b`, the tasks' default first."""
    return [name for name in BUILT_IN if follows_fig1b(build(name))]


def check_built_in(name: str) -> None:
    """ValueError naming the built-in layouts if ``name`` is not one of them."""
    if name in RENAMED:
        raise ValueError(f"layout {name!r} is now called {RENAMED[name]!r} (the default, "
                         f"{DEFAULT!r}, is the reconstruction of the paper's routing)")
    if name not in BUILT_IN:
        raise ValueError(f"unknown layout {name!r}; built-in layouts are {list(BUILT_IN)}")


def build(name: str, spec: arm_lib.ArmSpec | None = None) -> arm_lib.TendonLayout:
    """The built-in layout ``name`` on ``spec`` (default: Table 1's arm)."""
    check_built_in(name)
    return BUILT_IN[name].factory(spec or arm_lib.ArmSpec.from_table1())


def target_file(name: str) -> pathlib.Path:
    """The shipped level-pose target file of a built-in layout (``targets.generate``'s
    format): pass ``targets.training_targets(target_file(name))`` as ``target_pool``."""
    check_built_in(name)
    if name == DEFAULT:
        return targets.DATA_PATH
    path = DATA_DIR / f"level_head_poses_{name}.npz"
    if not path.exists():
        shipped = [DEFAULT] + sorted(p.stem.removeprefix("level_head_poses_")
                                     for p in DATA_DIR.glob("level_head_poses_*.npz"))
        raise FileNotFoundError(f"no target file ships for layout {name!r}; layouts with one: "
                                f"{shipped} (make one with robostrich-layouts --write-targets)")
    return path


def task_kwargs(name: str) -> dict:
    """``task_kwargs`` for the reaching tasks on built-in layout ``name`` with its own
    shipped targets, e.g. ``robostrich_suite.load("robostrich", "lesson2",
    task_kwargs=layouts.task_kwargs("antagonist_pairs"))``."""
    return dict(tendon_layout=build(name), target_pool=targets.training_targets(target_file(name)))


# --------------------------------------------------------------------------- files

TENDON_KEYS = ("name", "side", "links", "on_base", "from", "to", "hole_offset")
FILE_KEYS = ("name", "tendons")


def to_dict(layout: arm_lib.TendonLayout, name: str | None = None) -> dict:
    """The declarative form of ``layout`` (explicit ``links``; ``hole_offset`` where a tendon
    has its own): ``json.dumps`` it to start a file from a built-in."""
    tendons = [{"name": t.name, "side": t.side, "links": list(t.links), "on_base": t.on_base,
                **({} if t.hole_offset is None else {"hole_offset": float(t.hole_offset)})}
               for t in layout.tendons]
    return {"name": name, "tendons": tendons} if name else {"tendons": tendons}


def from_dict(data, spec: arm_lib.ArmSpec | None = None, source: str = "layout"
              ) -> arm_lib.TendonLayout:
    """A validated layout from its declarative form; errors name ``source`` and the item."""
    spec = spec or arm_lib.ArmSpec.from_table1()

    def fail(message):
        raise LayoutFileError(f"{source}: {message}")

    if not isinstance(data, dict):
        fail(f"expected a table/object with 'tendons', got {type(data).__name__}")
    unknown = sorted(set(data) - set(FILE_KEYS))
    if unknown:
        fail(f"unknown key(s) {unknown}; a layout file has {list(FILE_KEYS)}")
    if "name" in data and not isinstance(data["name"], str):
        fail(f"'name' must be a string, got {data['name']!r}")
    entries = data.get("tendons")
    if not isinstance(entries, list) or not entries:
        fail("'tendons' must be a non-empty list of tendons")
    tendons = tuple(_tendon_from_dict(entry, i, spec, fail) for i, entry in enumerate(entries, 1))
    layout = arm_lib.TendonLayout(tendons)
    try:
        layout.validate(spec)
    except ValueError as error:
        fail(str(error))
    return layout


def _tendon_from_dict(entry, i: int, spec: arm_lib.ArmSpec, fail) -> arm_lib.TendonSpec:
    """Tendon ``i`` (from 1) of a layout's declarative form; ``fail(message)`` raises."""
    label = f"tendon {i}"
    if not isinstance(entry, dict):
        fail(f"{label}: expected a table/object, got {type(entry).__name__}")
    if isinstance(entry.get("name"), str):
        label = f"tendon {i} ({entry['name']!r})"
    unknown = sorted(set(entry) - set(TENDON_KEYS))
    if unknown:
        fail(f"{label}: unknown key(s) {unknown}; a tendon has {list(TENDON_KEYS)}")
    for key in ("name", "side"):
        if not isinstance(entry.get(key), str):
            fail(f"{label}: '{key}' must be a string, got {entry.get(key)!r}")
    hole_offset = entry.get("hole_offset")
    low, high = arm_lib.HOLE_OFFSET_RANGE
    if "hole_offset" in entry and (isinstance(hole_offset, bool) or not isinstance(hole_offset, (int, float))
                                   or not math.isfinite(hole_offset) or not low <= hole_offset <= high):
        fail(f"{label}: 'hole_offset' must be a distance from {low} to {high} m (the holes' distance "
             f"from the joint axis), got {hole_offset!r}")
    hole_offset = None if hole_offset is None else float(hole_offset)
    has_links, has_span = "links" in entry, ("from" in entry or "to" in entry)
    if has_links == has_span:
        fail(f"{label}: give either 'links' (caudal to cranial) or 'from' and 'to'")
    if has_links:
        links = entry["links"]
        if not isinstance(links, list) or not all(isinstance(x, str) for x in links):
            fail(f"{label}: 'links' must be a list of link names, got {links!r}")
        on_base = entry.get("on_base", True)
        if not isinstance(on_base, bool):
            fail(f"{label}: 'on_base' must be true or false, got {on_base!r}")
        return arm_lib.TendonSpec(entry["name"], entry["side"], tuple(links), on_base, hole_offset)
    if "on_base" in entry:
        fail(f"{label}: 'on_base' goes with 'links'; with 'from' the base link means anchored on the base")
    for key in ("from", "to"):
        if not isinstance(entry.get(key), str):
            fail(f"{label}: '{key}' must be a link name, got {entry.get(key)!r}")
    try:
        spanning = arm_lib.TendonSpec.spanning(entry["name"], entry["side"], entry["to"], spec, origin=entry["from"])
    except ValueError as error:
        fail(str(error))
    return dataclasses.replace(spanning, hole_offset=hole_offset)


def read_file(path, spec: arm_lib.ArmSpec | None = None) -> tuple[str, arm_lib.TendonLayout]:
    """``(name, layout)`` from a ``.json`` or ``.toml`` file; the name defaults to the
    file's stem."""
    path = pathlib.Path(path)
    try:  # a regular file of bounded size, a FIFO refused at once (not waited on); a missing one: OSError
        text = input_files.read_bytes(path, MAX_FILE_BYTES, "layout file").decode("utf-8")
    except UnicodeDecodeError as error:
        raise LayoutFileError(f"{path}: not a UTF-8 text file (byte {error.start} cannot be decoded)") from None
    except ValueError as error:  # not a regular file, or too large
        raise LayoutFileError(str(error)) from None
    suffix = path.suffix.lower()
    try:
        if suffix == ".json":
            data = json.loads(text)
        elif suffix == ".toml":
            import tomllib
            data = tomllib.loads(text)
        else:
            raise LayoutFileError(f"{path}: unknown layout file type {path.suffix!r}; "
                                  "use .json or .toml")
    except (json.JSONDecodeError, ValueError, RecursionError) as error:
        if isinstance(error, LayoutFileError):
            raise
        what = "nested too deeply" if isinstance(error, RecursionError) else str(error)
        raise LayoutFileError(f"{path}: not valid {suffix[1:].upper()}: {what}") from None
    layout = from_dict(data, spec, source=str(path))
    return data.get("name") or path.stem, layout
