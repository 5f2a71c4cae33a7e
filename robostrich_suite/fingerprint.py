"""The model fingerprint: a short hash of what decides where the arm on its frame comes
to rest.  Target files carry the fingerprint of the arm they were made with, so a pose
set made with another arm is recognised as stale."""
from __future__ import annotations

import functools
import hashlib
import warnings

import numpy as np

from robostrich_suite import scenes, targets
from robostrich_suite.model import arm as arm_lib


def model_fingerprint(spec: arm_lib.ArmSpec | None = None,
                      layout: arm_lib.TendonLayout | None = None) -> str:
    """Short hash of what decides where the arm comes to rest; a pose set made with
    another arm is stale.  Colours, names and sensors do not count.  Kept per arm: every
    environment made for an arm other than the default asks for it."""
    try:
        return _kept_fingerprint(spec, layout)
    except TypeError:  # an unhashable spec: computed each time
        return compiled_fingerprint(scenes.frame_physics(spec, layout).model)


@functools.lru_cache(maxsize=16)
def _kept_fingerprint(spec, layout) -> str:
    return compiled_fingerprint(scenes.frame_physics(spec, layout).model)


def compiled_fingerprint(model) -> str:
    """:func:`model_fingerprint` of a compiled MuJoCo model (an environment's
    ``physics.model``): equal for the frame arm's domain and its frame physics."""
    digest = hashlib.sha256()
    for field in ("body_pos", "body_quat", "body_mass", "body_inertia", "jnt_range",
                  "jnt_stiffness", "jnt_solref", "jnt_solimp", "dof_damping", "dof_armature",
                  "site_pos", "geom_size", "actuator_gainprm", "actuator_biasprm",
                  "actuator_ctrlrange", "actuator_forcerange", "wrap_objid"):
        digest.update(np.round(np.asarray(getattr(model, field), np.float64), 9).tobytes())
    digest.update(np.array([model.opt.timestep, model.opt.integrator], np.float64).tobytes())
    return digest.hexdigest()[:16]


def warn_if_other_arm(spec=None, layout=None) -> bool:
    """Warn (and return True) when the shipped targets were made with another arm than
    ``spec``/``layout``: its level-head poses differ, so some targets may be out of reach
    or not holdable with a level head."""
    if spec is None and layout is None:
        return False
    shipped = str(targets.level_head_poses()["fingerprint"])
    if model_fingerprint(spec, layout) == shipped:
        return False
    warnings.warn(
        "the shipped targets were made with the default arm, not this arm spec/tendon layout; "
        "some may be unreachable. Make targets for it with robostrich_suite.studies.target_generation.generate("
        "..., spec=..., layout=..., path=FILE) and pass target_pool=training_targets(FILE).",
        stacklevel=3)
    return True
