"""Ray for robostrich-sweep: a local Ray started and stopped around the sweep (or an existing
cluster), and the task that runs one robostrich-train command on one core.

Ray is optional (``pip install -e '.[sweep]'``): nothing here imports it at module level, and
``import_ray`` turns its absence into one line that says how to install it.

A local Ray keeps its files (sockets, logs) under SWEEP/ray when that path is short enough for a
Unix socket, else in a fresh directory under the system's temporary directory that is removed when
the sweep ends; its authentication token is passed in the environment, not written to ~/.ray.
"""
import contextlib
import os
import secrets
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from agents.robostrich.sweep.table import TIMING_FILE
from robostrich_suite.atomic_files import write_text

INSTALL_HINT = "Ray is not installed; pip install -e '.[sweep]' (or pip install ray==2.60.0)"
# A Unix socket path holds at most 107 bytes; Ray puts its sockets below its temporary directory
# in a directory of 42 characters named by the start's date, time and process id, as
# sockets/plasma_store (a second socket of one name gets .1, .2, ...).
SOCKET_PATH_MAX = 107
SOCKET_TAIL = 1 + 42 + len("/sockets/plasma_store") + 3
# One intra-op thread per run, as robostrich-train's own workers have (agents/robostrich/train/command.py).
ONE_THREAD_XLA = "--xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1"
INTERRUPT_GRACE_S = 300  # how long an interrupted run may take to write its checkpoints
CONNECT_TIMEOUT_S = 10.0  # how long --address may stay silent before the sweep gives up
LAUNCHER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "run_launcher.py")
_LOCAL_TOKEN = secrets.token_hex(32)  # a local Ray's token: one per process (Ray keeps the first it reads)


def check_installed() -> None:
    """A ValueError naming how to install Ray where it is missing (robostrich_suite.cli: one line,
    exit 2), without importing it: Ray reads its settings from the environment when it is imported."""
    import importlib.util
    try:
        found = importlib.util.find_spec("ray") is not None
    except (ImportError, ValueError):
        found = False
    if not found:
        raise ValueError(INSTALL_HINT)


def import_ray():
    """The ray module, or the ValueError of check_installed."""
    try:
        import ray
    except ImportError:
        raise ValueError(INSTALL_HINT) from None
    return ray


def _fits(directory: str) -> bool:
    return len(os.path.abspath(directory).encode()) + SOCKET_TAIL <= SOCKET_PATH_MAX


def ray_temp_dir(out: str):
    """(directory, whether to remove it afterwards): OUT/ray if its sockets' paths fit, else a new
    directory under the system's temporary one (or /tmp, where that is too long as well)."""
    inside = os.path.join(os.path.abspath(out), "ray")
    if _fits(inside):
        os.makedirs(inside, exist_ok=True)
        return inside, False
    for parent in (tempfile.gettempdir(), "/tmp"):
        if _fits(os.path.join(parent, "robostrich-sweep-xxxxxxxx")) and os.path.isdir(parent):
            return tempfile.mkdtemp(prefix="robostrich-sweep-", dir=parent), True
    raise ValueError(f"no directory for Ray's sockets: {inside} and {tempfile.gettempdir()} are too long for a "
                     f"Unix socket (at most {SOCKET_PATH_MAX - SOCKET_TAIL} characters); give a shorter --out")


@contextlib.contextmanager
def _environment(**values):
    """os.environ with ``values`` set where the caller has not set them, as it was afterwards."""
    saved = {k: os.environ.get(k) for k in values}
    os.environ.update({k: v for k, v in values.items() if os.environ.get(k) is None})
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def check_reachable(address: str, timeout_s: float = CONNECT_TIMEOUT_S) -> None:
    """A ValueError naming ``address`` when nothing answers there within ``timeout_s``: Ray itself
    retries an absent cluster for minutes, with warnings of many lines, deaf to SIGTERM meanwhile."""
    import socket
    host, _, port = address.split("://")[-1].rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ValueError(f"--address {address}: expected host:port or ray://host:port")
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=timeout_s).close()
    except OSError as error:
        reason = error.strerror or str(error) or type(error).__name__
        raise ValueError(f"--address {address}: no Ray cluster answers there ({reason}, "
                         f"waited at most {timeout_s:g} s)") from None


@contextlib.contextmanager
def _own_stop_signals():
    """Ray's init sets a SIGTERM handler that exits the driver at once (its tasks unstopped, their
    checkpoints unwritten): the command's own handler is put back, so SIGTERM stops the sweep as
    Ctrl-C does."""
    handler = signal.getsignal(signal.SIGTERM)
    try:
        yield
    finally:
        if handler is not None and threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGTERM, handler)


def _init(ray, **kwargs):
    """ray.init quietly, the stop signals kept as the command set them."""
    with _own_stop_signals():
        ray.init(log_to_driver=False, logging_level="WARNING", **kwargs)


@contextlib.contextmanager
def connected(out: str, address=None, num_cpus=None):
    """Ray (the module) for the block: the cluster at ``address``, else a local one of ``num_cpus``
    CPUs (default: every core) started here and stopped when the block ends, however it ends."""
    if address is not None:
        ray = import_ray()
        try:
            try:
                _init(ray, address=address)
            except (ConnectionError, RuntimeError) as error:  # no cluster there, or one that refuses us
                raise ValueError(f"--address {address}: {' '.join(str(error).split())[:300]}") from None
            yield ray
        finally:
            ray.shutdown()
        return
    temp_dir, remove = ray_temp_dir(out)
    token = {} if os.environ.get("RAY_AUTH_TOKEN_PATH") else {"RAY_AUTH_TOKEN": _LOCAL_TOKEN}
    try:  # the token in the environment before Ray is imported: it reads its mode once
        with _environment(RAY_AUTH_MODE="token", RAY_USAGE_STATS_ENABLED="0", **token):
            ray = import_ray()
            try:  # a Ctrl-C while Ray starts stops what has started
                try:
                    _init(ray, num_cpus=num_cpus or os.cpu_count() or 1, include_dashboard=False, _temp_dir=temp_dir)
                except RuntimeError as error:  # e.g. its GCS did not come up; its logs are in temp_dir
                    raise ValueError(f"a local Ray did not start ({temp_dir}): "
                                     f"{' '.join(str(error).split())[:300]}") from None
                yield ray
            finally:
                ray.shutdown()
    finally:
        if remove:
            shutil.rmtree(temp_dir, ignore_errors=True)


def train_command() -> str:
    """The installed robostrich-train beside this Python (the worker's), else on PATH."""
    beside = os.path.join(os.path.dirname(sys.executable), "robostrich-train")
    found = beside if os.path.exists(beside) else shutil.which("robostrich-train")
    if found is None:
        raise FileNotFoundError(f"robostrich-train is not installed beside {sys.executable} nor on PATH")
    return found


def launch_command(argv: list) -> list:
    """The command line that runs robostrich-train with ``argv`` under the launcher
    (agents/robostrich/sweep/run_launcher.py: Ctrl-C reaches the run, and the run writes its checkpoint
    and ends when the worker that started it dies)."""
    return [sys.executable, LAUNCHER, str(os.getpid()), train_command(), *argv]


def last_error(log_path: str) -> str:
    """The training command's one-line error (``robostrich-train: error: ...``), else the last line
    of its output (a traceback's last line names the exception)."""
    try:
        with open(log_path, errors="replace") as f:
            lines = [line.strip() for line in f.read()[-20_000:].splitlines() if line.strip()]
    except OSError:
        return "no output"
    errors = [line for line in lines if line.startswith("robostrich-train: ")]
    return (errors or lines or ["no output"])[-1]


def _write_timing(run_dir: str, minutes: float, argv: list) -> None:
    """The wall-clock of the command that finished the run, beside its summary (sweep_table.run_minutes)."""
    import json
    write_text(os.path.join(run_dir, TIMING_FILE),
               json.dumps({"minutes": minutes, "resumed": "--resume" in argv, "argv": argv}, indent=1))


def _wait(process) -> int:
    """The exit status, waited for in short steps: ray.cancel interrupts the task's Python code
    between two, not a blocking wait."""
    while True:
        try:
            return process.wait(timeout=0.5)
        except subprocess.TimeoutExpired:
            continue


def _wait_until_unlocked(run_dir: str) -> None:
    """Wait (at most INTERRUPT_GRACE_S) while an earlier robostrich-train still holds the run's
    directory: a sweep started again at once after a killed one finds its runs still writing their
    checkpoints. Only waits: the run's own lock is what refuses a directory in use."""
    import fcntl
    path = os.path.join(run_dir, ".lock")
    deadline = time.time() + INTERRUPT_GRACE_S
    while os.path.exists(path) and time.time() < deadline:
        with open(path, "rb") as handle:
            try:
                fcntl.flock(handle, fcntl.LOCK_SH | fcntl.LOCK_NB)
            except BlockingIOError:
                time.sleep(0.2)
                continue
        return


def train_run(argv: list, run_dir: str) -> dict:
    """One robostrich-train command (a Ray task): its output in RUN_DIR/train.log (appended, so a
    resumed run's follows the earlier one's), Ctrl-C or a cancel forwarded so that it writes its
    checkpoints. Returns {"status": "done"|"failed"|"interrupted", "minutes", "error"}."""
    os.makedirs(run_dir, exist_ok=True)
    log_path = os.path.join(run_dir, "train.log")
    env = {**os.environ, "XLA_FLAGS": f"{os.environ.get('XLA_FLAGS', '')} {ONE_THREAD_XLA}".strip()}
    env.pop("RAY_AUTH_TOKEN", None)  # the cluster's, not the training's
    _wait_until_unlocked(run_dir)
    start = time.time()
    with open(log_path, "ab") as log:
        process = subprocess.Popen(launch_command(argv), stdout=log, stderr=subprocess.STDOUT, env=env)
        try:
            code = _wait(process)
        except KeyboardInterrupt:  # ray.cancel, or Ctrl-C
            process.send_signal(signal.SIGINT)
            try:
                code = process.wait(timeout=INTERRUPT_GRACE_S)
            except subprocess.TimeoutExpired:
                process.kill()
                code = process.wait()
    minutes = (time.time() - start) / 60.0
    if code == 0 and os.path.exists(os.path.join(run_dir, "summary.json")):
        _write_timing(run_dir, minutes, argv)
        return {"status": "done", "minutes": minutes, "error": None}
    stopped = (130, 143, -signal.SIGINT, -signal.SIGTERM)  # Ctrl-C or SIGTERM: checkpoints written, resumable
    status = "interrupted" if code in stopped else "failed"
    return {"status": status, "minutes": minutes, "error": f"{last_error(log_path)} (exit status {code}; log: {log_path})"}
