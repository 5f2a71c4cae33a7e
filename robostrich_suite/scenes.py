"""The scenes the arm is simulated in: the immobile frame and the A1 composition.

* the frame arena (:func:`build_frame_arm`): the paper's first setup, the arm's base on
  an immobile post, neck pointing up; :func:`frame_physics` compiles it for the studies
  into a :class:`FramePhysics`, which reads it through the one accessor layer
  (:class:`robostrich_suite.physics.ArmPhysicsMixin`);
* the A1 composition (:func:`build_a1`): the quadruped with the arm on its trunk, on a
  floor, optionally in front of the narrow-gap wall of Fig. 10 (``scene="narrow_gap"``).
"""
from __future__ import annotations

import numpy as np
from dm_control import mjcf, mujoco

from robostrich_suite import physics as physics_lib
from robostrich_suite import quadruped_physics
from robostrich_suite.model import arm as arm_lib
from robostrich_suite.model import quadruped as quad
from robostrich_suite.model.timesteps import PHYSICS_TIMESTEP


# --- the immobile frame ----------------------------------------------------------------
FRAME_HEIGHT = 0.05  # m, top of the immobile frame, where the arm's base sits


def _set_up_world(model: mjcf.RootElement, texrepeat: int) -> None:
    """What every scene shares: the physics timestep and integrator, the headlight and the
    checker floor material (repeated ``texrepeat`` times)."""
    model.option.timestep = PHYSICS_TIMESTEP
    model.option.integrator = "implicitfast"
    model.visual.headlight.set_attributes(ambient=[0.4, 0.4, 0.4], diffuse=[0.6, 0.6, 0.6])
    model.asset.add("texture", name="grid", type="2d", builtin="checker", width=256, height=256,
                    rgb1=[0.2, 0.3, 0.4], rgb2=[0.25, 0.35, 0.45])
    model.asset.add("material", name="grid", texture="grid", texrepeat=[texrepeat, texrepeat],
                    reflectance=0.1)


def build_frame_arm(spec: arm_lib.ArmSpec | None = None, layout: arm_lib.TendonLayout | None = None,
                    base_height: float = FRAME_HEIGHT) -> mjcf.RootElement:
    """The arm on an immobile frame (the paper's first setup), neck pointing up.

    The frame's top carries the arm's base; the base link's joint is at
    ``(0, 0, base_height + anchor_depth)`` in the world.
    """
    spec = spec or arm_lib.ArmSpec.from_table1()
    arena = mjcf.RootElement(model="robostrich")
    arena.compiler.angle = "radian"
    _set_up_world(arena, texrepeat=8)
    arena.worldbody.add("light", pos=[0, -1, 2], dir=[0, 1, -1])
    arena.worldbody.add("geom", name="floor", type="plane", size=[2, 2, 0.05], material="grid",
                        pos=[0, 0, -0.4])
    arena.worldbody.add("geom", name="frame_post", type="box", size=[0.02, 0.04, 0.2],
                        pos=[-0.02, 0, base_height - 0.2], rgba=[0.4, 0.4, 0.45, 1])
    arena.worldbody.add("camera", name="side", pos=[0.25, -1.4, 0.35], xyaxes=[1, 0, 0, 0, 0, 1])
    mount = arena.worldbody.add("site", name="arm_mount",
                                pos=[0, 0, base_height + spec.anchor_depth], size=[0.005])
    mount.attach(arm_lib.build_arm(spec, layout))
    return arena


class FramePhysics(physics_lib.ArmPhysicsMixin, mujoco.Physics):
    """The arm on its frame with the arm's accessors (head, joints, tendons) and
    divergence capture: a step that diverges sets ``divergence`` instead of raising,
    and steps are no-ops until the next ``reset``."""


def frame_physics(spec=None, layout=None) -> FramePhysics:
    """The arm on its frame, compiled at full XML precision (as ``mjcf.Physics.from_mjcf_model``
    does; the ``robostrich`` domain rounds its XML to 10 digits)."""
    model = build_frame_arm(spec, layout)
    return FramePhysics.from_xml_string(model.to_xml_string(), model.get_assets())


# --- the A1 composition ------------------------------------------------------------------
# Where the arm's first joint (C18) sits relative to the trunk centre, and the
# height it has when the quadruped stands at its nominal trunk height.
MOUNT_OFFSET = np.array([quad.MOUNT_X, 0.0, quad.TRUNK_SIZE[2] / 2 + quad.ARM_BASE_CLEARANCE])
NOMINAL_MOUNT_HEIGHT = quad.STANDING_TRUNK_HEIGHT + MOUNT_OFFSET[2]
FRAME_MOUNT_HEIGHT = FRAME_HEIGHT + arm_lib.ArmSpec.from_table1().anchor_depth  # build_frame_arm's C18

# narrow_gap scene (Fig. 10), x measured from the quadruped's start (trunk centre).
GAP_WALL_X = 1.0  # m, near face of the wall
GAP_WALL_TOP = 1.3  # m, the wall rises above anything the head reaches
GAP_SHELF_BOTTOM = 0.50  # m, underside of the overhang (a shelf behind the wall)
GAP_SHELF_THICKNESS = 0.03  # m
GAP_SLOT_X = 0.20  # m, slot centre behind the wall's near face
GAP_SLOT_WIDTH = 0.07  # m, along x: the neck is planar, so the slot is narrow in x only
GAP_SHELF_DEPTH = 0.45  # m, shelf extent behind the wall's near face
WALL_THICKNESS = 0.04  # m


class _StandingPhysics(quadruped_physics.QuadrupedPhysicsMixin, mujoco.Physics):
    """Places the composed robot in its standing pose for the ``stand`` keyframe."""


def build_a1(arm_spec=None, tendon_layout=None, scene: str = "flat") -> mjcf.RootElement:
    """Quadruped (free joint) + arm on the trunk + floor; ``scene`` "flat" or "narrow_gap".

    Built in the order ``dm_control.mjcf`` allows: the arm is attached to the trunk's
    mount site of a quadruped without a free joint, and only then is the free joint
    added.  The quadruped is the root model and the arena (floor, light, camera,
    obstacles) is added into it, rather than attaching the quadruped to an arena
    through a frame: that way the arm keeps its ``arm/`` names, which the shared arm
    accessors (``ArmPhysicsMixin``) and domain randomisation look up, instead of
    becoming ``a1/arm/...``.
    """
    if scene not in ("flat", "narrow_gap"):
        raise ValueError(f"unknown scene {scene!r}; use 'flat' or 'narrow_gap'")
    model = quad.build_quadruped()
    model.model = "robostrich_a1"
    model.find("site", quad.MOUNT_SITE).attach(arm_lib.build_arm(arm_spec, tendon_layout))
    trunk = model.find("body", quad.TRUNK_BODY)
    trunk.pos = [0, 0, quad.standing_hip_height()]
    trunk.insert("freejoint", 0, name="root")

    _set_up_world(model, texrepeat=20)
    model.worldbody.insert("light", 0, pos=[0, -1, 3], dir=[0, 0.3, -1])
    model.worldbody.insert("geom", 1, name="floor", type="plane", size=[10, 10, 0.1],
                           material="grid", friction=[1.0, 0.005, 0.0001])
    model.worldbody.add("camera", name="side", pos=[0.3, -2.0, 0.6], xyaxes=[1, 0, 0, 0, 0.2, 1],
                        mode="trackcom")
    if scene == "narrow_gap":
        _add_narrow_gap(model)
    _add_standing_keyframe(model)
    return model


def _add_standing_keyframe(arena: mjcf.RootElement) -> None:
    """Keyframe ``stand``: the standing pose with its servo targets, for plain MuJoCo users
    of the exported XML (at ``qpos0`` the knees are outside their range)."""
    physics = _StandingPhysics.from_xml_string(arena.to_xml_string())
    physics.place_standing()
    arena.keyframe.add("key", name="stand", qpos=np.round(physics.data.qpos, 6),
                       ctrl=np.round(physics.data.ctrl, 6))


def _add_narrow_gap(arena: mjcf.RootElement) -> None:
    """A wall taller than the head reaches, with a shelf behind it pierced by a narrow slot.

    Every obstacle geom has the arm's collision bit in ``conaffinity``: the arm touches it.
    """
    contact = dict(contype=1, conaffinity=1 | arm_lib.COLLISION_TYPE, rgba=[0.7, 0.5, 0.3, 1])
    wall_bottom = GAP_SHELF_BOTTOM + GAP_SHELF_THICKNESS
    x0, half_y = GAP_WALL_X, 0.6
    arena.worldbody.add("geom", name="gap_wall", type="box",
                        size=[WALL_THICKNESS / 2, half_y, (GAP_WALL_TOP - wall_bottom) / 2],
                        pos=[x0 - WALL_THICKNESS / 2, 0, (GAP_WALL_TOP + wall_bottom) / 2],
                        **contact)
    z = GAP_SHELF_BOTTOM + GAP_SHELF_THICKNESS / 2
    slot_near = GAP_SLOT_X - GAP_SLOT_WIDTH / 2
    slot_far = GAP_SLOT_X + GAP_SLOT_WIDTH / 2
    for name, start, end in (("gap_shelf_near", -WALL_THICKNESS, slot_near),
                             ("gap_shelf_far", slot_far, GAP_SHELF_DEPTH)):
        arena.worldbody.add("geom", name=name, type="box",
                            size=[(end - start) / 2, half_y, GAP_SHELF_THICKNESS / 2],
                            pos=[x0 + (start + end) / 2, 0, z], **contact)
    for side in (-1, 1):  # legs holding the shelf up, clear of the robot's path
        arena.worldbody.add("geom", name=f"gap_post_{'left' if side > 0 else 'right'}",
                            type="box", size=[0.02, 0.02, GAP_SHELF_BOTTOM / 2],
                            pos=[x0 + GAP_SHELF_DEPTH - 0.02, side * (half_y - 0.02),
                                 GAP_SHELF_BOTTOM / 2], **contact)
