"""Shared test set-up: headless MuJoCo (MUJOCO_GL=egl unless the environment sets it), the
checked-in models, one way to find an installed console script (``from conftest import
console_script``) and one way to check Rerun recordings."""
import os
import pathlib
import shutil
import subprocess
import sys

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")

RERUN_CLI_MISSING = ("the rerun command of rerun-sdk is not installed (neither beside this Python "
                     "nor on PATH): .rrd recordings not verified")


def rerun_cli() -> str | None:
    """The ``rerun`` command of rerun-sdk: beside this Python (an unactivated venv), else on PATH."""
    beside = pathlib.Path(sys.executable).parent / "rerun"
    return str(beside) if beside.exists() else shutil.which("rerun")


def console_script(name: str) -> str:
    """The installed console script ``name``: beside this Python (the venv's), else on PATH; the
    test skips if it is not installed."""
    beside = pathlib.Path(sys.executable).parent / name
    path = str(beside) if beside.exists() else shutil.which(name)
    if path is None:
        pytest.skip(f"{name} is not installed (pip install -e .)")
    return path


@pytest.fixture
def repo_xml_dir() -> pathlib.Path:
    """The checked-in generated models (``xml/``), which tests compare with the generators."""
    return pathlib.Path(__file__).resolve().parents[1] / "xml"


@pytest.fixture
def verify_rrd():
    """``verify_rrd(*paths)``: each .rrd must pass ``rerun rrd verify``.  Without the rerun
    command every test skips here with the one reason ``RERUN_CLI_MISSING``; call it after the
    test's other checks, which then still run."""
    cli = rerun_cli()

    def verify(*paths):
        if cli is None:
            pytest.skip(RERUN_CLI_MISSING)
        for path in paths:
            result = subprocess.run([cli, "rrd", "verify", str(path)], capture_output=True, text=True,
                                    timeout=300)
            assert result.returncode == 0, f"{path}: {result.stderr[-2000:]}"
    return verify
