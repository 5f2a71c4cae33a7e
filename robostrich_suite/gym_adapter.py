"""A gymnasium view of any robostrich_suite task, for libraries that speak gymnasium.

    from robostrich_suite import gym_adapter
    env = gym_adapter.make("robostrich", "lesson2", seed=0)
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

Observations are the dm_env dict flattened in its (stable) key order into one
float32 vector; ``env.observation_slices`` says which entries are which.  A
time-limit end (discount 1) is ``truncated``; a divergence (discount 0) is
``terminated``.  With ``normalize_actions=True`` (the default, as most gymnasium
agents expect) actions live in [-1, 1] and are mapped linearly onto the
tendon contraction range; pass False for contractions in metres.  Requires the ``gym`` extra: ``pip install -e '.[gym]'``.

Every task is registered with gymnasium when ``robostrich_suite`` is imported
(``robostrich/lesson2-v0``, ``robostrich_a1/head_stabilize-v0``, ...)::

    import gymnasium, robostrich_suite
    env = gymnasium.make("robostrich/lesson2-v0", render_mode="rgb_array", time_limit=1.0)

Keyword arguments other than ``render_mode``, ``seed``, ``normalize_actions``,
``width``, ``height`` and ``camera`` are the task's ``task_kwargs``.
``render_mode="rgb_array"`` makes ``render()`` return an (height, width, 3) uint8
frame from the model's ``side`` camera; it needs an offscreen OpenGL backend
(``MUJOCO_GL=egl``, or ``osmesa`` with libOSMesa installed), which
``robostrich_suite`` picks itself when no display is set.

``info`` (from ``reset`` and every ``step``) is what the reaching task measures at that step
(``robostrich_suite.tasks.measurement.Measurement``, the reading evaluation and recordings take):
``is_success`` (the task's own test: the head within its position and attitude tolerances),
``position_error`` (m), ``attitude_error`` (deg, signed: positive = head pitched down),
``target`` and ``head_position`` ((x, z) in m, the task's frame), ``head_attitude`` (deg),
``position_tolerance``, ``attitude_tolerance``, ``target_in_world`` and ``head_in_world``
((x, y, z) in m); plus ``divergence`` on the step where the physics diverged.
"""
from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium import spaces

import robostrich_suite
from robostrich_suite.tasks import measurement
from robostrich_suite.tasks.actions import validate_action


class GymnasiumEnv(gymnasium.Env):
    """Wraps a ``dm_env.Environment`` with dict observations and a bounded action."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 125}

    def __init__(self, dm_environment, normalize_actions: bool = True, render_mode: str | None = None,
                 width: int = 640, height: int = 480, camera: str = "side"):
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(f"render_mode must be None or one of {self.metadata['render_modes']}, "
                             f"got {render_mode!r}")
        if not (isinstance(width, int) and isinstance(height, int) and width > 0 and height > 0):
            raise ValueError(f"width and height must be positive whole numbers of pixels, got {width!r}, {height!r}")
        visual = dm_environment.physics.model.vis.global_
        if width > visual.offwidth or height > visual.offheight:  # the model's offscreen framebuffer
            raise ValueError(f"width x height {width} x {height} exceeds the model's offscreen framebuffer "
                             f"({visual.offwidth} x {visual.offheight} pixels)")
        self.dm_env = dm_environment
        self.render_mode = render_mode
        self.width, self.height, self.camera = width, height, camera
        # One frame per control step (0.008 s: 125 frames per second).
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / dm_environment.control_timestep()))}
        action_spec = dm_environment.action_spec()
        self._action_low = np.asarray(action_spec.minimum, np.float64)
        self._action_high = np.asarray(action_spec.maximum, np.float64)
        self.normalize_actions = normalize_actions
        if normalize_actions:
            ones = np.ones(action_spec.shape, np.float32)
            self.action_space = spaces.Box(-ones, ones, dtype=np.float32)
        else:
            self.action_space = spaces.Box(self._action_low.astype(np.float32),
                                           self._action_high.astype(np.float32), dtype=np.float32)
        self.observation_slices = {}
        start = 0
        for name, spec in dm_environment.observation_spec().items():
            size = int(np.prod(spec.shape))
            self.observation_slices[name] = slice(start, start + size)
            start += size
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(start,), dtype=np.float32)

    def _flatten(self, observation) -> np.ndarray:
        return np.concatenate([np.asarray(v, np.float32).ravel() for v in observation.values()])

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        if seed is not None:
            self.dm_env.task.random.seed(seed)
            # A seeded reset is a fresh start: lesson 3 must not carry over the last pose,
            # or two resets with one seed would differ (gymnasium's determinism check).
            forget = getattr(self.dm_env.task, "forget_last_state", None)
            if forget is not None:
                forget()
        timestep = self.dm_env.reset()
        self._episode_over = False
        return self._flatten(timestep.observation), self._measures()

    def _measures(self) -> dict:
        """What the task measures now (gymnasium's ``info``): its measurement, for a task with a
        target (every reaching task); nothing for one without."""
        measured = measurement.measure(self.dm_env)
        return measured.as_dict() if measured.target is not None else {}

    def to_dm_action(self, action) -> np.ndarray:
        """The dm_env action (contractions in metres) for a gymnasium action."""
        action = validate_action(action, self._action_low.size)
        if not self.normalize_actions:
            return action
        return self._action_low + (action + 1.0) * 0.5 * (self._action_high - self._action_low)

    def step(self, action):
        if getattr(self, "_episode_over", True):
            raise gymnasium.error.ResetNeeded(
                "cannot call step() before reset() or after the episode ended; call reset()")
        timestep = self.dm_env.step(self.to_dm_action(action))
        self._episode_over = timestep.last()
        terminated = timestep.last() and timestep.discount == 0.0
        truncated = timestep.last() and not terminated
        info = self._measures()
        if getattr(self.dm_env.physics, "divergence", None):
            info["divergence"] = self.dm_env.physics.divergence
        return (self._flatten(timestep.observation), float(timestep.reward), bool(terminated),
                bool(truncated), info)

    def render(self):
        """An (height, width, 3) uint8 frame of the scene (``render_mode="rgb_array"``); None
        (with gymnasium's warning) when the environment was made without a render mode."""
        if self.render_mode is None:
            gymnasium.logger.warn("render() called without a render_mode; make the environment "
                                  "with render_mode='rgb_array'")
            return None
        import mujoco
        physics = self.dm_env.physics
        # -1 (MuJoCo's free camera) for a model without that camera
        camera = mujoco.mj_name2id(physics.model.ptr, mujoco.mjtObj.mjOBJ_CAMERA, str(self.camera))
        return physics.render(height=self.height, width=self.width, camera_id=camera)


def make(domain_name: str, task_name: str, seed: int | None = None,
         normalize_actions: bool = True, render_mode: str | None = None, width: int = 640,
         height: int = 480, camera: str = "side", **task_kwargs) -> GymnasiumEnv:
    """``robostrich_suite.load`` + the gymnasium wrapper (also the entry point of the
    registered ``DOMAIN/TASK-v0`` environments)."""
    if seed is not None:
        task_kwargs["random"] = seed
    return GymnasiumEnv(robostrich_suite.load(domain_name, task_name, task_kwargs=task_kwargs),
                        normalize_actions=normalize_actions, render_mode=render_mode,
                        width=width, height=height, camera=camera)


make.metadata = GymnasiumEnv.metadata  # gymnasium.make reads the entry point's render modes here
