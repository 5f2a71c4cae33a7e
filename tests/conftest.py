"""Shared test set-up: headless MuJoCo (MUJOCO_GL=egl unless the environment sets it), the
checked-in models, one way to find an installed console script (``from conftest import
console_script``), one way to run it as a user would (``start`` / ``finish``, sharing one XLA
cache for the whole run, ``shared_jax_cache``) and ways to check Rerun recordings (``verify_rrd``,
``rrd_entities``, ``rrd_view_names``).
The scripts of ``tools/`` import as modules (``import results_page``)."""
import json
import os
import pathlib
import shutil
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]  # the repository

os.environ.setdefault("MUJOCO_GL", "egl")
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "tools"))

def pytest_configure(config):
    config.addinivalue_line("markers", "long: runs for tens of seconds; scheduled first (see below)")


def pytest_collection_modifyitems(items):
    """The modules with long tests first, each kept whole (its module-scoped fixtures, a finished
    sweep or a shared XLA cache, are then set up once): the workers of ``-n 2`` share out the short
    modules as they free up and finish together, instead of one starting a minute-long test when the
    other has nothing left."""
    long_modules = {item.module.__name__ for item in items if item.get_closest_marker("long")}
    items.sort(key=lambda item: item.module.__name__ not in long_modules)


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


# The environment installed commands run in: headless, and (``shared_jax_cache``) one persistent XLA
# cache for the whole test run, so a process reuses every earlier one's compilations.
COMMAND_ENVIRONMENT = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
JAX_CACHE_SETTINGS = {  # a size limit turns on JAX's file lock, which both xdist workers need
    "jax_persistent_cache_min_compile_time_secs": 0, "jax_persistent_cache_min_entry_size_bytes": 0,
    "jax_compilation_cache_max_size": 8 << 30}


@pytest.fixture(scope="session", autouse=True)
def shared_jax_cache(tmp_path_factory):
    """One XLA cache for the test run, shared by both xdist workers, the commands they start and
    the tests' own processes: compiling the learner's update is most of a tiny training's work; and
    one cache of the project's (ROBOSTRICH_CACHE) in the run's temporary folder."""
    base = tmp_path_factory.getbasetemp()
    cache = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "jax_cache"
    cache.mkdir(exist_ok=True)
    settings = {"jax_compilation_cache_dir": str(cache), **JAX_CACHE_SETTINGS}
    variables = {name.upper(): str(value) for name, value in settings.items()}
    # the project's own cache (new targets made, the lookup's evaluations) for the run, not the user's home
    variables["ROBOSTRICH_CACHE"] = str(cache.parent / "robostrich_cache")
    os.environ.update(variables)
    COMMAND_ENVIRONMENT.update(variables)
    import jax
    for name, value in settings.items():
        jax.config.update(name, value)


def start(name, *args, cwd=None) -> subprocess.Popen:
    """The installed command ``name`` started with ``args``, its output captured."""
    return subprocess.Popen([console_script(name), *map(str, args)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=COMMAND_ENVIRONMENT, cwd=cwd)


def finish(process, timeout=600) -> subprocess.CompletedProcess:
    stdout, stderr = process.communicate(timeout=timeout)
    return subprocess.CompletedProcess(process.args, process.returncode, stdout, stderr)


# Runs each (command, arguments) through the entry point its console script calls
# (robostrich_commands.launch), one after another in this one process.
_IN_ONE_PROCESS = r"""
import contextlib, io, json, sys
from robostrich_commands import launch
results = {}
for case, (prog, args) in json.loads(sys.stdin.read()).items():
    sys.argv = [prog, *args]
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        try:
            status = launch(prog)
        except SystemExit as stop:
            status = stop.code if isinstance(stop.code, int) else int(stop.code is not None)
    results[case] = [status, stdout.getvalue(), stderr.getvalue()]
sys.__stdout__.write(json.dumps(results))
"""


def run_in_one_process(cases: dict, cwd=None, env=None, timeout=600) -> dict:
    """``{case: (command, [arguments])}`` -> ``{case: CompletedProcess}``, each as the installed command
    would end (status, stdout, stderr), from one Python process: commands that stop at their flags'
    checks then cost one start-up of JAX and MuJoCo in all, not one each."""
    payload = {case: [name, [str(a) for a in args]] for case, (name, args) in cases.items()}
    done = subprocess.run([sys.executable, "-c", _IN_ONE_PROCESS], input=json.dumps(payload), capture_output=True,
                          text=True, env=env or COMMAND_ENVIRONMENT, cwd=cwd, timeout=timeout)
    assert done.returncode == 0, done.stderr[-3000:]
    return {case: subprocess.CompletedProcess([cases[case][0], *payload[case][1]], status, out, err)
            for case, (status, out, err) in json.loads(done.stdout).items()}


def rrd_entities(path) -> set:
    """The entity paths of the first recording in the .rrd file ``path`` (read by rerun-sdk's reader)."""
    import rerun as rr
    return set(rr.chunk.RrdReader(str(path)).stream().collect().schema().entity_paths())


def rrd_view_names(path) -> list:
    """The names of the views in the first blueprint of the .rrd (or .rbl) file ``path``, in no set
    order; [] if it carries no blueprint."""
    import rerun as rr
    reader = rr.chunk.RrdReader(str(path))
    if not reader.blueprints():
        return []
    names = []
    for chunk in reader.stream(store=reader.blueprints()[0]).to_chunks():
        batch = chunk.to_record_batch()
        for column in batch.schema.names:
            if column.endswith("ViewBlueprint:display_name"):
                names += [name for row in batch.column(column).to_pylist() for name in row]
    return names
