"""Shared test set-up: headless MuJoCo (MUJOCO_GL=egl unless the environment sets it)."""
import os
import pathlib

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")


@pytest.fixture
def repo_xml_dir() -> pathlib.Path:
    """The checked-in generated models (``xml/``), which tests compare with the generators."""
    return pathlib.Path(__file__).resolve().parents[1] / "xml"
