"""Shared test set-up: headless MuJoCo (MUJOCO_GL=egl unless the environment sets it)."""
import os

os.environ.setdefault("MUJOCO_GL", "egl")
