"""The A1-like quadruped's leg kinematics: two-link inverse and forward kinematics in the leg's
sagittal plane, the trunk heights the legs can hold, and the standing pose.

Facts of the model, below the physics and the tasks: the physics places the standing quadruped
with them and the gaits (``tasks/gait.py``) turn foot paths into joint targets with them.
"""
from __future__ import annotations

import math

import numpy as np

from robostrich_suite.model import quadruped as quad

# The leg servos (kp 100) sag under the robot's weight: measured trunk height minus
# command, at 0.22-0.28 m, is -0.010 m standing and -0.019 m on average while trotting.
# The tasks command the legs that much higher so the trunk's height matches the command.
SAG_COMPENSATION = {"stand": 0.010, "walk": 0.019}  # m
L1, L2 = quad.THIGH_LENGTH, quad.CALF_LENGTH
# Trunk heights the legs can hold while trotting (knee limits with the stride's reach).
MIN_TRUNK_HEIGHT = 0.16  # m
MAX_TRUNK_HEIGHT = 0.35  # m


def leg_ik(foot_x, foot_z):
    """(hip, knee) angles placing the foot at ``(foot_x, foot_z)`` from the hip, in the
    leg's sagittal plane (x forward, z up, ``foot_z < 0``).  Knee bent backwards (< 0).

    Out-of-reach points are clamped onto the reachable annulus.
    """
    if np.ndim(foot_x) == 1 and len(foot_x) <= 4:  # one control step: plain floats are faster
        return _leg_ik_few(foot_x, foot_z)
    foot_x, foot_z = np.asarray(foot_x, float), np.asarray(foot_z, float)
    dist2 = foot_x ** 2 + foot_z ** 2
    cos_knee = np.clip((dist2 - L1 ** 2 - L2 ** 2) / (2 * L1 * L2), -1.0, 1.0)
    knee = -np.arccos(cos_knee)
    # Angle of the hip->foot line from straight down (positive towards -x), minus the
    # angle that the bent knee adds to it.
    direction = np.arctan2(-foot_x, -foot_z)
    bend = np.arctan2(L2 * np.sin(knee), L1 + L2 * np.cos(knee))
    return direction - bend, knee


def _leg_ik_few(foot_x, foot_z):
    hips, knees = [], []
    for x, z in zip(foot_x.tolist() if hasattr(foot_x, "tolist") else foot_x,
                    foot_z.tolist() if hasattr(foot_z, "tolist") else foot_z):
        cos_knee = min(max((x * x + z * z - L1 * L1 - L2 * L2) / (2 * L1 * L2), -1.0), 1.0)
        knee = -math.acos(cos_knee)
        hips.append(math.atan2(-x, -z) - math.atan2(L2 * math.sin(knee), L1 + L2 * math.cos(knee)))
        knees.append(knee)
    return np.array(hips), np.array(knees)


def leg_fk(hip, knee):
    """Foot position ``(x, z)`` from the hip for (hip, knee) angles: inverse of :func:`leg_ik`."""
    hip, knee = np.asarray(hip, float), np.asarray(knee, float)
    x = -L1 * np.sin(hip) - L2 * np.sin(hip + knee)
    z = -L1 * np.cos(hip) - L2 * np.cos(hip + knee)
    return x, z


def check_trunk_height(trunk_height) -> None:
    if isinstance(trunk_height, float):  # the per-step path: no numpy overhead
        if MIN_TRUNK_HEIGHT <= trunk_height <= MAX_TRUNK_HEIGHT:
            return
    else:
        height = np.asarray(trunk_height, float)
        if (np.all(np.isfinite(height)) and np.all(height >= MIN_TRUNK_HEIGHT)
                and np.all(height <= MAX_TRUNK_HEIGHT)):
            return
    raise ValueError(f"trunk height {trunk_height} m is outside the range the legs can hold "
                     f"[{MIN_TRUNK_HEIGHT}, {MAX_TRUNK_HEIGHT}] m")


def foot_depth(trunk_height):
    """Vertical distance from hip to foot centre for a trunk (= hip) height above ground."""
    return np.asarray(trunk_height, float) - quad.FOOT_RADIUS


def assemble(hip, knee):
    """(..., 4) hip and knee angles -> (..., 12) targets, abduction 0 (feet under the thighs)."""
    targets = np.zeros(hip.shape[:-1] + (12,))
    targets[..., 1::3] = hip
    targets[..., 2::3] = knee
    return targets


def standing_joint_targets(trunk_height: float) -> np.ndarray:
    """The 12 joint targets with every foot under its hip and the trunk ``trunk_height`` above the ground."""
    check_trunk_height(trunk_height)
    hip, knee = leg_ik(np.zeros(4), -np.broadcast_to(foot_depth(trunk_height), ())[..., None] * np.ones(4))
    return assemble(hip, knee)
