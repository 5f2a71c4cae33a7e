"""Shared test set-up: headless MuJoCo and the repository root on sys.path."""
import os

os.environ.setdefault("MUJOCO_GL", "egl")
