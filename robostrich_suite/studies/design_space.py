"""The routings ``robostrich-design`` searches: the paper's constraints, every choice left open.

The paper's robot has Table 1's links, one dorsal and eight ventral tendons, each through
run-through holes of every link between its origin and its insertion.  Its text leaves the
rest open, so a routing here is, per tendon: the insertion link, how many joints caudal its
origin is tied (at the base at most, where it is anchored on the base), and its holes' offset
from the joint axis (its moment arm, :data:`HOLE_OFFSETS`).  With ``stiffness`` the passive
joint stiffness is searched too, within the stiffness sweep's range (docs/layouts.md).

Beyond the paper's family (:class:`Space`): other counts of dorsal and ventral tendons
(:data:`DORSAL_RANGE`, :data:`VENTRAL_RANGE`), and holes that skip links: a tendon's *stride*
(1 to ``max_stride``) is how many links apart its holes are, counted from the insertion, the
origin always holed.  A tendon that skips links bowstrings over the ones between: its moment arm
about their joints grows as the neck bends there, where a run-through tendon's stays the hole
offset; that is the one other insertion the generator builds without new geometry (a layout file's
``links`` already may skip), so it is the one searched.

A trial's parameters are named ``dorsal_insertion``, ``dorsal_span``, ``dorsal_offset`` (further
dorsal tendons ``dorsal_K_...``, K = 2..) and ``ventral_K_...`` for K = 1..N, ``..._stride`` with a
stride to search; :func:`parameters` gives them for a layout (to start a search from a known
routing), :func:`layout` the layout of a trial.
"""
from __future__ import annotations

import dataclasses

from robostrich_suite.model import arm as arm_lib

VENTRAL_TENDONS = 8  # the paper's
DORSAL_TENDONS = 1  # the paper's
VENTRAL_RANGE = (2, 16)  # the movement tests need two ventral tendons; 16 is twice the paper's
DORSAL_RANGE = (1, 4)
STRIDE_RANGE = (1, 4)  # a stride of 4 leaves 4-5 holes on a tendon through all 17 joints
HOLE_OFFSETS = (0.008, 0.025)  # m searched: a hole at the vertebra's surface (8 mm) up to a process of 25 mm
STIFFNESS = (0.5, 4.0)  # N m/rad searched (log-uniform): the stiffness sweep's range
SPEC = arm_lib.ArmSpec.from_table1()


@dataclasses.dataclass(frozen=True)
class Space:
    """How many tendons of each side a routing has, and the widest stride of its holes (1: every link)."""
    dorsal: int = DORSAL_TENDONS
    ventral: int = VENTRAL_TENDONS
    max_stride: int = 1

    def tendon_names(self) -> list[str]:
        return (["dorsal"] + [f"dorsal_{k}" for k in range(2, self.dorsal + 1)]
                + [f"ventral_{k}" for k in range(1, self.ventral + 1)])

    def is_papers(self) -> bool:
        return self == Space()


PAPER = Space()


def tendon_names(space: Space = PAPER) -> list[str]:
    return space.tendon_names()


def suggest(trial, stiffness: bool = False, space: Space = PAPER) -> dict:
    """A trial's parameters (``trial.suggest_*``): insertion index (0 the head, 16 C17),
    span in joints, hole offset (and stride, when ``space`` allows more than 1), per tendon; the
    stiffness with ``stiffness``."""
    last = SPEC.num_joints - 1
    params = {}
    for name in space.tendon_names():
        params[f"{name}_insertion"] = trial.suggest_int(f"{name}_insertion", 0, last - 1)
        params[f"{name}_span"] = trial.suggest_int(f"{name}_span", 1, last)
        params[f"{name}_offset"] = trial.suggest_float(f"{name}_offset", *HOLE_OFFSETS)
        if space.max_stride > 1:
            params[f"{name}_stride"] = trial.suggest_int(f"{name}_stride", 1, space.max_stride)
    if stiffness:
        params["stiffness"] = trial.suggest_float("stiffness", *STIFFNESS, log=True)
    return params


def holes(insertion: int, origin: int, stride: int) -> tuple[str, ...]:
    """The links holed (caudal to cranial) from ``origin`` to ``insertion`` (joint indices, 0 the
    head) every ``stride`` links from the insertion, the origin always."""
    names = SPEC.joint_names
    indices = sorted(set(range(insertion, origin, stride)) | {origin}, reverse=True)
    return tuple(names[i] for i in indices)


def layout(params: dict) -> arm_lib.TendonLayout:
    """The routing of a trial's parameters: the dorsal tendons first (the most cranial insertion
    first, named ``dorsal``, then ``dorsal_2``...), the ventral ones caudal to cranial."""
    names = SPEC.joint_names
    keys = sorted({key[:-len("_insertion")] for key in params if key.endswith("_insertion")},
                  key=lambda k: (k.split("_")[0] != "dorsal", int(k.split("_")[1]) if "_" in k else 1))
    dorsal, ventral = [], []
    for name in keys:
        insertion = int(params[f"{name}_insertion"])
        origin = min(insertion + int(params[f"{name}_span"]), len(names) - 1)
        side = name.split("_")[0]
        tendon = arm_lib.TendonSpec(name, side, holes(insertion, origin, int(params.get(f"{name}_stride", 1))),
                                    on_base=origin == len(names) - 1,
                                    hole_offset=round(float(params[f"{name}_offset"]), 5))
        (dorsal if side == "dorsal" else ventral).append(tendon)
    dorsal = sorted(dorsal, key=lambda t: names.index(t.insertion) * 100 - len(t.links))
    dorsal = [dataclasses.replace(t, name="dorsal" if k == 1 else f"dorsal_{k}") for k, t in enumerate(dorsal, 1)]
    ventral = sorted(ventral, key=lambda t: -names.index(t.insertion) * 100 - len(t.links))
    ventral = [dataclasses.replace(t, name=f"ventral_{k}") for k, t in enumerate(ventral, 1)]
    return arm_lib.TendonLayout((*dorsal, *ventral))


def spec(params: dict) -> arm_lib.ArmSpec:
    """Table 1's arm, at the trial's stiffness if it has one."""
    return SPEC if "stiffness" not in params else arm_lib.ArmSpec.from_table1(joint_stiffness=params["stiffness"])


def parameters(layout_: arm_lib.TendonLayout, stiffness: float | None = None, space: Space = PAPER) -> dict:
    """The parameters of ``layout_``, which must be in ``space`` (ValueError saying why not)."""
    names = SPEC.joint_names
    dorsal = [t for t in layout_.tendons if t.side == "dorsal"]
    ventral = [t for t in layout_.tendons if t.side == "ventral"]
    if len(dorsal) != space.dorsal or len(ventral) != space.ventral:
        raise ValueError(f"the search's routings have {space.dorsal} dorsal and {space.ventral} ventral tendons, "
                         f"this one {len(dorsal)} and {len(ventral)}")
    params = {}
    for name, tendon in zip(space.tendon_names(), dorsal + ventral):
        insertion, origin = names.index(tendon.insertion), names.index(tendon.links[0])
        stride = names.index(tendon.links[-2]) - insertion
        if (stride > space.max_stride or tendon.links != holes(insertion, origin, stride)
                or tendon.on_base != (origin == len(names) - 1)):
            raise ValueError(f"tendon {tendon.name!r} skips links or is tied short of the base at the base link; "
                             "the search's tendons run through every link from origin to insertion"
                             + (f" (or holes up to {space.max_stride} links apart)" if space.max_stride > 1 else ""))
        offset = tendon.offset(SPEC)
        if not HOLE_OFFSETS[0] <= offset <= HOLE_OFFSETS[1]:
            raise ValueError(f"tendon {tendon.name!r}: hole offset {offset} m is outside the search's {HOLE_OFFSETS}")
        params.update({f"{name}_insertion": insertion, f"{name}_span": origin - insertion,
                       f"{name}_offset": offset, **({f"{name}_stride": stride} if space.max_stride > 1 else {})})
    if stiffness is not None:
        params["stiffness"] = float(stiffness)
    return params
