"""MJCF generator for tendon-driven planar necks such as the Robostrich arm.

The arm is a chain of passive hinge joints in the sagittal (x-z) plane.  Every
link has two run-through holes (sites), one on its dorsal and one on its ventral
side; each tendon is a spatial tendon from an anchor on the base, through the
holes of the links it is listed with, to its insertion link.  One ``general``
actuator per tendon servos the tendon's *contraction* and can only pull.

Conventions (used by every other module):

* The chain leaves the base along the base body's +z axis, caudal (C18) first,
  cranial (atlas/head) last.  Joints turn about +y.
* A positive joint angle is **ventral** flexion: it turns the cranial part of
  the neck towards +x, the ventral (throat) side.  Joint ranges are therefore
  ``[-dorsal_limit, +ventral_limit]``.  Ventral holes sit at +x, dorsal at -x.
* On the immobile frame the neck stands up (+z) and the animal faces +x, so
  ventral flexion brings the head forward and down.  The head attitude is the
  angle of the head's axis from the vertical: 0 deg pointing up, 90 deg level
  (the paper's Fig. 2B), 180 deg pointing down.
* Actuator control = tendon contraction in metres (target length = rest length
  minus control).  Negative control lets the tendon pay out (go slack).

Everything the generator needs comes from an :class:`ArmSpec` (by default
:func:`ArmSpec.from_table1`) and a :class:`TendonLayout` (by default
:func:`TendonLayout.robostrich`).  Bad specs and layouts raise ``ValueError``
naming the offending item.
"""
from __future__ import annotations

import dataclasses

import numpy as np
from dm_control import mjcf

from robostrich_suite.model import table1
from robostrich_suite.model.timesteps import PHYSICS_TIMESTEP

SIDES = ("dorsal", "ventral")
ARM_MODEL_NAME = "arm"
HEAD_SITE = "head"
HEAD_VELOCITY_SENSOR = "head_velocity"
COLLISION_TYPE = 2  # contype of arm geoms; obstacles the arm may touch set this bit in conaffinity.
# The arm's own bit: its links collide with each other (as vertebrae do), and with nothing
# else that does not set COLLISION_TYPE in its conaffinity.
SELF_COLLISION_TYPE = 4
# m: a tendon's own hole offset (moment arm) stays between a hole just outside the 8 mm
# vertebra's axis and a process about twice the default 15 mm: the paper's arm is
# 3-D printed at this scale, and a farther hole would stand off links 7-44 mm long.
HOLE_OFFSET_RANGE = (0.004, 0.04)


@dataclasses.dataclass(frozen=True)
class ArmSpec:
    """Geometry, inertia and passive/actuator parameters of a planar tendon neck.

    Sequences run cranial (head) to caudal (base), one entry per joint.  The
    first joint's body is the head; ``link_lengths`` has one entry fewer than
    ``joint_names`` (the head's length is ``head_length``).
    """
    joint_names: tuple[str, ...]
    dorsal_limits_deg: tuple[float, ...]
    ventral_limits_deg: tuple[float, ...]
    link_lengths: tuple[float, ...]  # metres, for joint_names[1:]
    masses: tuple[float, ...]  # kilograms, head first
    head_length: float = 0.06  # m, skull + beak along the head axis
    head_site_fraction: float = 0.5  # where along the head its "position" is measured
    link_radius: float = 0.008  # m, capsule radius of each vertebra
    hole_offset: float = 0.015  # m, distance of the run-through holes from the joint axis line
    hole_fraction: float = 0.5  # where along a link its holes are (0 caudal joint, 1 cranial joint)
    anchor_depth: float = 0.03  # m, tendon anchors sit this far below the first joint on the base
    # Passive intervertebral joint: a plausible neck neither collapses under its own
    # weight nor rings for seconds.  Stiffness is per joint, towards the straight pose.
    joint_stiffness: float = 1.0  # N m / rad
    joint_damping: float = 0.1  # N m s / rad
    joint_armature: float = 2e-4  # kg m^2; keeps the 5 g links stable at 2 ms steps
    # Joint limits are soft constraints; on links this light a default limit lets a
    # 100 N tendon push a joint 10-20 deg past Table 1.  These keep it within ~0.5 deg
    # without chattering at the 2 ms physics step (measured over random tendon inputs).
    limit_solref: tuple[float, float] = (0.008, 1.0)
    limit_solimp: tuple[float, float, float] = (0.95, 0.99, 0.001)
    # Tendon servo: force = -kp (length - (rest - contraction)) - kv d(length)/dt, pull only.
    tendon_kp: float = 4000.0  # N / m
    tendon_kv: float = 40.0  # N s / m
    tendon_max_force: float = 150.0  # N, upper bound of the pull

    @classmethod
    def from_table1(cls, **overrides) -> "ArmSpec":
        """The Robostrich arm of the paper's Table 1 (SI units)."""
        spec = cls(
            joint_names=table1.JOINT_NAMES,
            dorsal_limits_deg=tuple(float(x) for x in table1.DORSAL_LIMIT_DEG),
            ventral_limits_deg=tuple(float(x) for x in table1.VENTRAL_LIMIT_DEG),
            link_lengths=tuple(x / 1000.0 for x in table1.LENGTH_MM[1:]),
            masses=tuple(x / 1000.0 for x in table1.MASS_G),
        )
        return dataclasses.replace(spec, **overrides)

    @property
    def head_name(self) -> str:
        return self.joint_names[0]

    @property
    def base_link(self) -> str:
        return self.joint_names[-1]

    @property
    def num_joints(self) -> int:
        return len(self.joint_names)

    def joint_range_rad(self) -> np.ndarray:
        """(num_joints, 2) array of [min, max] angles in radians (dorsal negative)."""
        return np.stack([-np.radians(self.dorsal_limits_deg),
                         np.radians(self.ventral_limits_deg)], axis=1)

    def validate(self) -> None:
        """Raise ``ValueError`` naming the first inconsistent entry."""
        n = len(self.joint_names)
        if n < 2:
            raise ValueError(f"an arm needs at least 2 joints, got {n}")
        for name in self.joint_names:
            _check_name(name, "joint/link name")
        numbers = [(f, getattr(self, f)) for f in ("dorsal_limits_deg", "ventral_limits_deg", "link_lengths",
                                                    "masses", "limit_solref", "limit_solimp")]
        numbers += [(f.name, getattr(self, f.name)) for f in dataclasses.fields(self)
                    if isinstance(getattr(self, f.name), float)]
        for field, value in numbers:  # NaN and inf pass the sign checks below and fail deep in MuJoCo
            if not np.all(np.isfinite(np.asarray(value, np.float64))):
                raise ValueError(f"{field} must be finite, got {value}")
        if len(set(self.joint_names)) != n:
            dup = sorted({x for x in self.joint_names if self.joint_names.count(x) > 1})
            raise ValueError(f"duplicate joint/link names: {dup}")
        for field, expected in (("dorsal_limits_deg", n), ("ventral_limits_deg", n),
                                ("masses", n), ("link_lengths", n - 1)):
            got = len(getattr(self, field))
            if got != expected:
                raise ValueError(f"{field} has {got} entries, expected {expected} "
                                 f"(one per joint{'' if expected == n else ' except the head'})")
        for name, dorsal, ventral in zip(self.joint_names, self.dorsal_limits_deg,
                                         self.ventral_limits_deg):
            if not (0 <= dorsal < 180):
                raise ValueError(f"joint {name!r}: dorsal limit {dorsal} deg must be in [0, 180)"
                                 " (a positive magnitude; the sign convention is applied for you)")
            if not (0 <= ventral < 180):
                raise ValueError(f"joint {name!r}: ventral limit {ventral} deg must be in [0, 180)"
                                 " (a positive magnitude; the sign convention is applied for you)")
        for name, mass in zip(self.joint_names, self.masses):
            if not mass > 0:
                raise ValueError(f"link {name!r}: mass {mass} kg must be positive")
        for name, length in zip(self.joint_names[1:], self.link_lengths):
            if not length > 0:
                raise ValueError(f"link {name!r}: length {length} m must be positive")
        for field in ("head_length", "link_radius", "hole_offset", "tendon_kp",
                      "tendon_max_force", "joint_armature"):
            if not getattr(self, field) > 0:
                raise ValueError(f"{field} must be positive, got {getattr(self, field)}")
        for field in ("joint_stiffness", "joint_damping", "tendon_kv", "anchor_depth"):
            if getattr(self, field) < 0:
                raise ValueError(f"{field} must be non-negative, got {getattr(self, field)}")
        for field in ("hole_fraction", "head_site_fraction"):
            if not 0 <= getattr(self, field) <= 1:
                raise ValueError(f"{field} must be in [0, 1], got {getattr(self, field)}")


def _check_name(name, what: str) -> None:
    """Names end up in MJCF names and the tab-joined action-spec name: printable, no tab/newline."""
    if not isinstance(name, str) or not name or not name.isprintable() or name != name.strip():
        raise ValueError(f"{what} {name!r} must be a non-empty printable string without "
                         "tabs, newlines or surrounding spaces")


@dataclasses.dataclass(frozen=True)
class TendonSpec:
    """One tendon through the holes of ``links`` (caudal to cranial) on ``side``.

    The last link in ``links`` is the insertion.  With ``on_base`` (default) the
    tendon starts at an anchor on the base, below the first joint, and the
    servo pulls it there.  Without, it is tied at the hole of ``links[0]`` and
    acts only on the joints between its first and last link, like one slip of a
    neck muscle running between two vertebrae (the servo is an idealised
    length actuator of that stretch).  Either way a tendon needs at least two
    holes.

    ``hole_offset`` (m) is this tendon's own distance of its holes (and anchor) from the
    joint axis line, its moment arm about every joint it crosses; None keeps the arm's
    ``ArmSpec.hole_offset``.  It is bounded by :data:`HOLE_OFFSET_RANGE`.
    """
    name: str
    side: str
    links: tuple[str, ...]
    on_base: bool = True
    hole_offset: float | None = None

    def offset(self, spec: "ArmSpec") -> float:
        """The distance of this tendon's holes from the joint axis line (m)."""
        return spec.hole_offset if self.hole_offset is None else float(self.hole_offset)

    @property
    def insertion(self) -> str:
        return self.links[-1]

    @classmethod
    def spanning(cls, name: str, side: str, insertion: str, spec: ArmSpec,
                 origin: str | None = None) -> "TendonSpec":
        """A tendon through every link from ``origin`` to ``insertion``.

        Without ``origin`` (or with the base link) it is anchored on the base; with
        another link, it is tied at that link's hole (``on_base=False``).
        """
        names = spec.joint_names
        origin = origin or spec.base_link
        for link in (origin, insertion):
            if link not in names:
                raise ValueError(f"tendon {name!r}: unknown link {link!r}; links are {list(names)}")
        i, j = names.index(insertion), names.index(origin)
        if i > j:
            raise ValueError(f"tendon {name!r}: insertion {insertion!r} is caudal of origin {origin!r}")
        return cls(name, side, tuple(reversed(names[i:j + 1])), on_base=origin == spec.base_link)


@dataclasses.dataclass(frozen=True)
class TendonLayout:
    """An ordered set of tendons; the order is the order of the actions."""
    tendons: tuple[TendonSpec, ...]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(t.name for t in self.tendons)

    def __len__(self) -> int:
        return len(self.tendons)

    # Default insertions of the 8 ventral tendons, caudal to cranial.  The paper
    # follows the ventral neck muscles of the ostrich (Cobley et al., 2013), whose
    # slips insert along the whole neck; we insert one tendon at every second
    # vertebra from C16 to C2, so each one adds flexion torque to a further
    # stretch of the neck.  Contracting them one after another moves the bend
    # along the neck (rolling pattern); the C2 tendon reaches the head joint
    # region and so steers the head's attitude.
    ROBOSTRICH_VENTRAL_INSERTIONS = ("c16", "c14", "c12", "c10", "c8", "c6", "c4", "c2")

    @classmethod
    def robostrich(cls, spec: ArmSpec | None = None) -> "TendonLayout":
        """The default layout, our reconstruction of the paper's Fig. 1B: 1 dorsal tendon
        to the head + 8 ventral slips (:meth:`ventral_slips`; docs/layouts.md says why)."""
        return cls.ventral_slips(spec)

    @classmethod
    def ventral_from_base(cls, spec: ArmSpec | None = None) -> "TendonLayout":
        """1 dorsal tendon to the head + 8 ventral tendons, each anchored on the base."""
        spec = spec or ArmSpec.from_table1()
        dorsal = TendonSpec.spanning("dorsal", "dorsal", spec.head_name, spec)
        ventral = [TendonSpec.spanning(f"ventral_{link}", "ventral", link, spec)
                   for link in cls.ROBOSTRICH_VENTRAL_INSERTIONS]
        return cls((dorsal, *ventral))

    @classmethod
    def ventral_slips(cls, spec: ArmSpec | None = None, span: int = 4) -> "TendonLayout":
        """The paper's dorsal tendon with 8 ventral *slips*: each inserts where the
        default layout's ventral tendon does but is tied ``span`` joints caudal of its
        insertion (at the base at most), like the overlapping slips of the ostrich's
        M. longus colli ventralis.  Each slip then bends only its own stretch of the
        neck instead of everything between the base and its insertion."""
        spec = spec or ArmSpec.from_table1()
        if not isinstance(span, int) or span < 1:
            raise ValueError(f"span must be a positive number of joints, got {span!r}")
        names = spec.joint_names
        dorsal = TendonSpec.spanning("dorsal", "dorsal", spec.head_name, spec)
        ventral = []
        for link in cls.ROBOSTRICH_VENTRAL_INSERTIONS:
            if link not in names:
                raise ValueError(f"ventral slips: the spec has no link {link!r}; "
                                 f"links are {list(names)}")
            origin = names[min(names.index(link) + span, len(names) - 1)]
            ventral.append(TendonSpec.spanning(f"ventral_{link}", "ventral", link, spec,
                                               origin=origin))
        return cls((dorsal, *ventral))

    def validate(self, spec: ArmSpec) -> None:
        """Raise ``ValueError`` naming the first bad tendon."""
        if not self.tendons:
            raise ValueError("a tendon layout needs at least one tendon")
        order = {name: i for i, name in enumerate(reversed(spec.joint_names))}  # caudal = 0
        seen = set()
        for tendon in self.tendons:
            _check_name(tendon.name, "tendon name")
            if tendon.name in seen:
                raise ValueError(f"duplicate tendon name {tendon.name!r}")
            seen.add(tendon.name)
            if tendon.side not in SIDES:
                raise ValueError(f"tendon {tendon.name!r}: unknown side {tendon.side!r}; "
                                 f"use one of {SIDES}")
            if len(tendon.links) < 2:
                raise ValueError(f"tendon {tendon.name!r} runs through {len(tendon.links)} hole(s);"
                                 " a tendon needs at least two")
            for link in tendon.links:
                if link not in order:
                    raise ValueError(f"tendon {tendon.name!r} runs through unknown link {link!r}; "
                                     f"links are {list(spec.joint_names)}")
            if tendon.hole_offset is not None:
                low, high = HOLE_OFFSET_RANGE
                if (isinstance(tendon.hole_offset, bool) or not isinstance(tendon.hole_offset, (int, float))
                        or not np.isfinite(tendon.hole_offset) or not low <= tendon.hole_offset <= high):
                    raise ValueError(f"tendon {tendon.name!r}: hole_offset {tendon.hole_offset!r} must be a "
                                     f"distance from {low} to {high} m")
            ranks = [order[link] for link in tendon.links]
            if any(b <= a for a, b in zip(ranks, ranks[1:])):
                raise ValueError(f"tendon {tendon.name!r}: links {list(tendon.links)} must run "
                                 "from caudal to cranial without repeats")


def hole_site_name(link: str, side: str, tendon: str | None = None) -> str:
    """The hole of ``link`` on ``side`` (shared by the tendons at the arm's hole offset), or
    ``tendon``'s own hole there; every hole's name ends in ``_{side}_hole``."""
    return f"{link}_{side}_hole" if tendon is None else f"{tendon}_at_{link}_{side}_hole"


def _anchor_site_name(tendon: str) -> str:
    return f"{tendon}_anchor"


def build_arm(spec: ArmSpec | None = None, layout: TendonLayout | None = None) -> mjcf.RootElement:
    """Return the arm as an ``mjcf`` model rooted at a fixed ``base`` body.

    Attach it to a frame or a robot with ``site.attach(build_arm())``; all names
    are then prefixed ``arm/``.  The base body holds the tendon anchors.
    """
    spec = ArmSpec.from_table1() if spec is None else spec
    spec.validate()
    layout = TendonLayout.robostrich(spec) if layout is None else layout
    if not isinstance(layout, TendonLayout):
        raise TypeError(f"tendon layout must be a TendonLayout, got {type(layout).__name__} {layout!r} "
                        "(robostrich_suite.model.layouts.build(name) makes a built-in one)")
    layout.validate(spec)

    model = mjcf.RootElement(model=ARM_MODEL_NAME)
    model.compiler.angle = "radian"
    model.option.integrator = "implicitfast"
    model.option.timestep = PHYSICS_TIMESTEP
    _add_defaults(model, spec)
    base = model.worldbody.add("body", name="base")
    base.add("geom", name="base_plate", type="box", size=[0.03, 0.02, 0.005],
             pos=[0, 0, -spec.anchor_depth - 0.005], contype=COLLISION_TYPE, conaffinity=0,
             rgba=[0.3, 0.3, 0.3, 1], mass=0.05)
    side_x = {"dorsal": -spec.hole_offset, "ventral": spec.hole_offset}
    bodies = _add_chain(model, base, spec, side_x)
    _add_tendons(model, base, spec, layout, bodies)
    _exclude_touching_links(model, spec)
    _add_tendon_servos(model, spec, layout)
    return model


def _add_defaults(model: mjcf.RootElement, spec: ArmSpec) -> None:
    """The ``link`` class (capsules, limited hinges with the passive spring) and the ``tendon`` class."""
    link_default = model.default.add("default", dclass="link")
    link_default.geom.set_attributes(type="capsule", size=[spec.link_radius],
                                     contype=COLLISION_TYPE | SELF_COLLISION_TYPE,
                                     conaffinity=SELF_COLLISION_TYPE, condim=1,
                                     rgba=[0.85, 0.8, 0.7, 1])
    link_default.joint.set_attributes(type="hinge", axis=[0, 1, 0], limited=True,
                                      stiffness=spec.joint_stiffness, damping=spec.joint_damping,
                                      armature=spec.joint_armature, springref=0,
                                      solreflimit=spec.limit_solref,
                                      solimplimit=spec.limit_solimp)
    link_default.site.set_attributes(type="sphere", size=[0.002], rgba=[0.2, 0.2, 0.9, 1])
    tendon_default = model.default.add("default", dclass="tendon")
    tendon_default.tendon.set_attributes(width=0.0015)
    tendon_default.general.set_attributes(
        gaintype="fixed", biastype="affine", ctrllimited=True, forcelimited=True,
        forcerange=[-spec.tendon_max_force, 0.0])


def _add_chain(model: mjcf.RootElement, base, spec: ArmSpec, side_x: dict) -> dict:
    """The links, caudal -> cranial (the base link's joint at the base origin), with their holes and the head site;
    returns {link: (body, length)} for the tendons' own holes."""
    joint_range = dict(zip(spec.joint_names, spec.joint_range_rad()))
    masses = dict(zip(spec.joint_names, spec.masses))
    lengths = dict(zip(spec.joint_names[1:], spec.link_lengths))
    parent, pos, bodies = base, 0.0, {}
    for name in reversed(spec.joint_names):
        body = parent.add("body", name=name, pos=[0, 0, pos], childclass="link")
        body.add("joint", name=name, range=joint_range[name])
        length = lengths.get(name, spec.head_length)
        if name == spec.head_name:
            body.add("geom", name=f"{name}_geom", fromto=[0, 0, 0, 0, 0, length],
                     size=[_link_geom_radius(spec, name)], mass=masses[name], rgba=[0.9, 0.6, 0.3, 1])
            head_site = body.add("site", name=HEAD_SITE,
                                 pos=[0, 0, spec.head_site_fraction * length],
                                 size=[0.004], rgba=[1, 0, 0, 1])
            model.sensor.add("framelinvel", name=HEAD_VELOCITY_SENSOR, objtype="site",
                             objname=head_site)
        else:
            body.add("geom", name=f"{name}_geom", fromto=[0, 0, 0, 0, 0, length], mass=masses[name])
        for side in SIDES:
            body.add("site", name=hole_site_name(name, side),
                     pos=[side_x[side], 0, spec.hole_fraction * length])
        parent, pos, bodies[name] = body, length, (body, length)
    return bodies


def _add_tendons(model: mjcf.RootElement, base, spec: ArmSpec, layout: TendonLayout, bodies: dict) -> None:
    """Each tendon from its anchor on the base (if it starts there) through its links' holes:
    the shared holes, or the tendon's own at its ``hole_offset``."""
    for tendon in layout.tendons:
        x = tendon.offset(spec) * (1.0 if tendon.side == "ventral" else -1.0)
        own = tendon.hole_offset is not None and tendon.offset(spec) != spec.hole_offset
        element = model.tendon.add("spatial", name=tendon.name, dclass="tendon",
                                   rgba=[0.1, 0.5, 0.9, 1] if tendon.side == "ventral"
                                   else [0.9, 0.2, 0.2, 1])
        if tendon.on_base:
            anchor = base.add("site", name=_anchor_site_name(tendon.name),
                              pos=[x, 0, -spec.anchor_depth],
                              size=[0.003], rgba=[0.2, 0.7, 0.2, 1])
            element.add("site", site=anchor)
        for link in tendon.links:
            if own:
                body, length = bodies[link]
                body.add("site", name=hole_site_name(link, tendon.side, tendon.name),
                         pos=[x, 0, spec.hole_fraction * length])
            element.add("site", site=hole_site_name(link, tendon.side, tendon.name if own else None))


def _link_geom_radius(spec: ArmSpec, name: str) -> float:
    return spec.link_radius * (1.6 if name == spec.head_name else 1.0)


def touching_link_pairs(spec: ArmSpec) -> list[tuple[str, str]]:
    """Pairs of links two or more joints apart whose capsules already touch in the
    straight pose (the links between them are shorter than the two radii): they are
    neighbours in all but name, so they do not collide.  MuJoCo leaves out the
    parent-child pairs itself; every other pair of links collides."""
    caudal_to_cranial = list(reversed(spec.joint_names))
    lengths = dict(zip(spec.joint_names[1:], spec.link_lengths))
    pairs = []
    for i, first in enumerate(caudal_to_cranial):
        for j in range(i + 2, len(caudal_to_cranial)):
            second = caudal_to_cranial[j]
            gap = sum(lengths[name] for name in caudal_to_cranial[i + 1:j])
            if gap <= _link_geom_radius(spec, first) + _link_geom_radius(spec, second):
                pairs.append((first, second))
    return pairs


def _exclude_touching_links(model: mjcf.RootElement, spec: ArmSpec) -> None:
    for first, second in touching_link_pairs(spec):
        model.contact.add("exclude", name=f"{first}_{second}", body1=first, body2=second)


def _add_tendon_servos(model: mjcf.RootElement, spec: ArmSpec, layout: TendonLayout) -> None:
    """One pull-only contraction servo per tendon, ranges derived from the joint limits.

    The rest length is the tendon's length in the straight pose.  The largest
    useful contraction is the shortening at the side's own joint limits; the
    largest release is the lengthening at the opposite limits.
    """
    physics = mjcf.Physics.from_mjcf_model(model)
    joint_names = list(spec.joint_names)
    tendon_names = list(layout.names)
    rest = np.array(physics.named.data.ten_length[tendon_names])
    limits = spec.joint_range_rad()

    def lengths_at(qpos):
        with physics.reset_context():
            physics.named.data.qpos[joint_names] = qpos
        return np.array(physics.named.data.ten_length[tendon_names])

    at_dorsal, at_ventral = lengths_at(limits[:, 0]), lengths_at(limits[:, 1])
    kp, kv = spec.tendon_kp, spec.tendon_kv
    for tendon, rest_length, dorsal_len, ventral_len in zip(layout.tendons, rest, at_dorsal,
                                                           at_ventral):
        own, other = (ventral_len, dorsal_len) if tendon.side == "ventral" else (dorsal_len,
                                                                                 ventral_len)
        max_contraction = max(rest_length - own, 1e-3)
        max_release = max(other - rest_length, 1e-3)
        model.actuator.add(
            "general", name=tendon.name, tendon=tendon.name, dclass="tendon",
            ctrlrange=[-round(max_release, 4), round(max_contraction, 4)],
            gainprm=[-kp], biasprm=[kp * rest_length, -kp, -kv])


HEAD_SITE_PATH = f"{ARM_MODEL_NAME}/{HEAD_SITE}"


def reach(spec: ArmSpec) -> float:
    """Distance from the base joint to the head site with the neck straight (m): no
    pose puts the head farther from the base joint than this."""
    return float(sum(spec.link_lengths) + spec.head_site_fraction * spec.head_length)
