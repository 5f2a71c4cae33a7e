"""The routings ``robostrich-design`` searches: the paper's constraints, every choice left open.

The paper's robot has Table 1's links, one dorsal and eight ventral tendons, each through
run-through holes of every link between its origin and its insertion.  Its text leaves the
rest open, so a routing here is, per tendon: the insertion link, how many joints caudal its
origin is tied (at the base at most, where it is anchored on the base), and its holes' offset
from the joint axis (its moment arm, :data:`HOLE_OFFSETS`).  With ``stiffness`` the passive
joint stiffness is searched too, within the stiffness sweep's range (docs/layouts.md).

A trial's parameters are named ``dorsal_insertion``, ``dorsal_span``, ``dorsal_offset`` and
``ventral_K_...`` for K = 1..8; :func:`parameters` gives them for a layout (to start a search
from a known routing), :func:`layout` the layout of a trial.
"""
from __future__ import annotations

import dataclasses

from robostrich_suite.model import arm as arm_lib

VENTRAL_TENDONS = 8
HOLE_OFFSETS = (0.008, 0.025)  # m searched: a hole at the vertebra's surface (8 mm) up to a process of 25 mm
STIFFNESS = (0.5, 4.0)  # N m/rad searched (log-uniform): the stiffness sweep's range
SPEC = arm_lib.ArmSpec.from_table1()


def tendon_names() -> list[str]:
    return ["dorsal"] + [f"ventral_{k}" for k in range(1, VENTRAL_TENDONS + 1)]


def suggest(trial, stiffness: bool = False) -> dict:
    """A trial's parameters (``trial.suggest_*``): insertion index (0 the head, 16 C17),
    span in joints, hole offset, per tendon; the stiffness with ``stiffness``."""
    last = SPEC.num_joints - 1
    params = {}
    for name in tendon_names():
        params[f"{name}_insertion"] = trial.suggest_int(f"{name}_insertion", 0, last - 1)
        params[f"{name}_span"] = trial.suggest_int(f"{name}_span", 1, last)
        params[f"{name}_offset"] = trial.suggest_float(f"{name}_offset", *HOLE_OFFSETS)
    if stiffness:
        params["stiffness"] = trial.suggest_float("stiffness", *STIFFNESS, log=True)
    return params


def layout(params: dict) -> arm_lib.TendonLayout:
    """The routing of a trial's parameters: dorsal first, the ventral tendons caudal to cranial."""
    names = SPEC.joint_names
    tendons = []
    for name in tendon_names():
        insertion = int(params[f"{name}_insertion"])
        origin = min(insertion + int(params[f"{name}_span"]), len(names) - 1)
        tendon = arm_lib.TendonSpec.spanning(name, name.split("_")[0], names[insertion], SPEC, origin=names[origin])
        tendons.append(dataclasses.replace(tendon, hole_offset=round(float(params[f"{name}_offset"]), 5)))
    ventral = sorted(tendons[1:], key=lambda t: -names.index(t.insertion) * 100 - len(t.links))
    ventral = [dataclasses.replace(t, name=f"ventral_{k}") for k, t in enumerate(ventral, 1)]
    return arm_lib.TendonLayout((tendons[0], *ventral))


def spec(params: dict) -> arm_lib.ArmSpec:
    """Table 1's arm, at the trial's stiffness if it has one."""
    return SPEC if "stiffness" not in params else arm_lib.ArmSpec.from_table1(joint_stiffness=params["stiffness"])


def parameters(layout_: arm_lib.TendonLayout, stiffness: float | None = None) -> dict:
    """The parameters of ``layout_``, which must be in the space (ValueError saying why not)."""
    names = SPEC.joint_names
    dorsal = [t for t in layout_.tendons if t.side == "dorsal"]
    ventral = [t for t in layout_.tendons if t.side == "ventral"]
    if len(dorsal) != 1 or len(ventral) != VENTRAL_TENDONS:
        raise ValueError(f"the search's routings have 1 dorsal and {VENTRAL_TENDONS} ventral tendons, "
                         f"this one {len(dorsal)} and {len(ventral)}")
    params = {}
    for name, tendon in zip(tendon_names(), dorsal + ventral):
        insertion, origin = names.index(tendon.insertion), names.index(tendon.links[0])
        if tendon.links != tuple(reversed(names[insertion:origin + 1])) or tendon.on_base != (origin == len(names) - 1):
            raise ValueError(f"tendon {tendon.name!r} skips links or is tied short of the base at the base link; "
                             "the search's tendons run through every link from origin to insertion")
        offset = tendon.offset(SPEC)
        if not HOLE_OFFSETS[0] <= offset <= HOLE_OFFSETS[1]:
            raise ValueError(f"tendon {tendon.name!r}: hole offset {offset} m is outside the search's {HOLE_OFFSETS}")
        params.update({f"{name}_insertion": insertion, f"{name}_span": origin - insertion,
                       f"{name}_offset": offset})
    if stiffness is not None:
        params["stiffness"] = float(stiffness)
    return params
