"""MJCF generator for an A1-like quadruped (public Unitree A1 facts, no downloaded model).

Every number about the robot is a named constant in this module.  The model
is built *without* a free joint so that the arm can be attached to its trunk
first: ``dm_control.mjcf`` refuses to attach a child whose top body has a free
joint.  The composition (:func:`robostrich_suite.scenes.build_a1`)
attaches the arm to ``MOUNT_SITE``, then adds the free joint to the trunk and
the arena (floor, light, obstacles) into this root model.

Conventions (those of the A1): the trunk faces +x, +y is the robot's left.
Legs are ``FR, FL, RR, RL``; each has an abduction joint (``{leg}_hip``, about
x), a hip joint (``{leg}_thigh``, about y) and a knee (``{leg}_calf``, about
y).  At zero angles the leg hangs straight down; a positive hip angle swings
the knee backwards, the knee angle is negative (the knee points backwards).
The 12 joints and their position servos are in that order (leg-major).
"""
from __future__ import annotations

import numpy as np
from dm_control import mjcf

MODEL_NAME = "a1"

# --- Unitree A1 facts (public specifications) -------------------------------------------
TRUNK_SIZE = (0.25, 0.08, 0.114)  # m, full box sizes (length, width, height)
TRUNK_MASS = 4.713  # kg
HIP_OFFSET = (0.183, 0.047, 0.0)  # m, |x|, |y|, z of the hips from the trunk centre
HIP_MASS = 0.696  # kg
THIGH_OFFSET_Y = 0.08505  # m, thigh body from the hip body along y (outwards)
THIGH_MASS = 1.013  # kg
THIGH_LENGTH = 0.2  # m
CALF_MASS = 0.226  # kg
CALF_LENGTH = 0.2  # m
FOOT_RADIUS = 0.02  # m
ABDUCTION_RANGE = (-0.8029, 0.8029)  # rad
HIP_RANGE = (-1.0472, 4.1888)  # rad
KNEE_RANGE = (-2.6965, -0.9163)  # rad
SERVO_KP = 100.0  # N m / rad
SERVO_FORCE_LIMIT = 33.5  # N m
STANDING_POSE = (0.0, 0.9, -1.8)  # (abduction, hip, knee) rad, every leg
STANDING_TRUNK_HEIGHT = 0.27  # m, approximately, in the standing pose
TOTAL_MASS = TRUNK_MASS + 4 * (HIP_MASS + THIGH_MASS + CALF_MASS)  # 12.45 kg

# --- modelling choices (not A1 facts) ---------------------------------------
JOINT_DAMPING = 1.0  # N m s / rad: damps the position servos (A1 models use 0.5-2)
JOINT_ARMATURE = 0.01  # kg m^2: rotor inertia seen at the joint, keeps 2 ms steps stable
FOOT_FRICTION = 0.8
MOUNT_SITE = "arm_mount"
MOUNT_X = 0.09  # m, arm mount from the trunk centre, towards the front
ARM_BASE_CLEARANCE = 0.04  # m, the arm's base plate hangs this far below its base origin

LEGS = ("FR", "FL", "RR", "RL")
LEG_SIGNS = {"FR": (1, -1), "FL": (1, 1), "RR": (-1, -1), "RL": (-1, 1)}  # (x, y) of the hip
JOINT_KINDS = ("hip", "thigh", "calf")
JOINT_NAMES = tuple(f"{leg}_{kind}" for leg in LEGS for kind in JOINT_KINDS)
JOINT_RANGES = np.array([ABDUCTION_RANGE, HIP_RANGE, KNEE_RANGE] * len(LEGS))  # (12, 2)
STANDING_TARGETS = np.array(STANDING_POSE * len(LEGS))  # (12,)
TRUNK_BODY = "trunk"
FOOT_GEOM = "{leg}_foot"


def standing_hip_height(pose=STANDING_POSE) -> float:
    """Height of the hips (= trunk centre) above the ground for a leg pose, feet down."""
    _, hip, knee = pose
    return float(THIGH_LENGTH * np.cos(hip) + CALF_LENGTH * np.cos(hip + knee) + FOOT_RADIUS)


def build_quadruped(mount_x: float = MOUNT_X) -> mjcf.RootElement:
    """The A1-like quadruped, trunk at the origin, no free joint (see module doc).

    ``MOUNT_SITE`` is on top of the trunk, ``mount_x`` forward of its centre,
    high enough that an attached arm's base plate rests on the trunk.
    """
    model = mjcf.RootElement(model=MODEL_NAME)
    model.compiler.angle = "radian"
    leg = model.default.add("default", dclass="leg")
    leg.joint.set_attributes(type="hinge", limited=True, damping=JOINT_DAMPING,
                             armature=JOINT_ARMATURE)
    leg.geom.set_attributes(contype=1, conaffinity=1, condim=3,
                            friction=[FOOT_FRICTION, 0.02, 0.01],
                            rgba=[0.25, 0.25, 0.28, 1])
    leg.position.set_attributes(kp=SERVO_KP, forcelimited=True, ctrllimited=True,
                                forcerange=[-SERVO_FORCE_LIMIT, SERVO_FORCE_LIMIT])

    trunk = model.worldbody.add("body", name=TRUNK_BODY)
    half = np.array(TRUNK_SIZE) / 2
    trunk.add("geom", name="trunk", type="box", size=half, mass=TRUNK_MASS,
              rgba=[0.15, 0.15, 0.17, 1])
    trunk.add("site", name="imu", pos=[0, 0, 0], size=[0.01])
    trunk.add("site", name=MOUNT_SITE, pos=[mount_x, 0, half[2] + ARM_BASE_CLEARANCE],
              size=[0.005], rgba=[0, 0, 0, 0])

    # Only the feet and the trunk collide: leg links never touch the ground in a trot,
    # and self-contacts between the links of one leg would make the servos chatter.
    for name in LEGS:
        sx, sy = LEG_SIGNS[name]
        hip = trunk.add("body", name=f"{name}_hip",
                        pos=[sx * HIP_OFFSET[0], sy * HIP_OFFSET[1], HIP_OFFSET[2]],
                        childclass="leg")
        hip.add("joint", name=f"{name}_hip", axis=[1, 0, 0], range=ABDUCTION_RANGE)
        hip.add("geom", name=f"{name}_hip", type="cylinder", size=[0.046, 0.02],
                quat=[0.7071068, 0.7071068, 0, 0], mass=HIP_MASS, contype=0, conaffinity=0)
        thigh = hip.add("body", name=f"{name}_thigh", pos=[0, sy * THIGH_OFFSET_Y, 0])
        thigh.add("joint", name=f"{name}_thigh", axis=[0, 1, 0], range=HIP_RANGE)
        thigh.add("geom", name=f"{name}_thigh", type="capsule", size=[0.018],
                  fromto=[0, 0, 0, 0, 0, -THIGH_LENGTH], mass=THIGH_MASS, contype=0, conaffinity=0)
        calf = thigh.add("body", name=f"{name}_calf", pos=[0, 0, -THIGH_LENGTH])
        calf.add("joint", name=f"{name}_calf", axis=[0, 1, 0], range=KNEE_RANGE)
        calf.add("geom", name=f"{name}_calf", type="capsule", size=[0.012],
                 fromto=[0, 0, 0, 0, 0, -CALF_LENGTH + FOOT_RADIUS], mass=CALF_MASS * 0.9,
                 contype=0, conaffinity=0)
        calf.add("geom", name=FOOT_GEOM.format(leg=name), type="sphere", size=[FOOT_RADIUS],
                 pos=[0, 0, -CALF_LENGTH], mass=CALF_MASS * 0.1, rgba=[0.1, 0.1, 0.1, 1])
        calf.add("site", name=f"{name}_foot", pos=[0, 0, -CALF_LENGTH], size=[0.005])

    for joint_name, (low, high) in zip(JOINT_NAMES, JOINT_RANGES):
        model.actuator.add("position", name=joint_name, joint=joint_name, dclass="leg",
                           ctrlrange=[low, high])
    return model
