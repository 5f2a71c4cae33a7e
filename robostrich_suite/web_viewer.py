"""``--web``: a command's recordings served in the browser by the web viewer that rerun-sdk bundles.

Once the command has written its ``.rrd`` files, rerun-sdk's own ``rerun`` program serves them on
127.0.0.1 only (the SDK's in-process servers listen on every interface): the viewer's page on
``--web-port`` and the gRPC server that holds the recordings on the port after it. No display and
no native viewer are needed; a browser on this machine, or on another through an SSH tunnel of both
ports (``ssh -L 9090:127.0.0.1:9090 -L 9091:127.0.0.1:9091 HOST``), opens the printed URL, in the
layout the files carry (robostrich_suite.rerun_blueprint).
The command then waits: Ctrl-C stops the servers (exit 130, robostrich_suite/cli.py).

    add_flags(parser); ...; check(args)   # before any work: a busy port is one line, exit 2
    serve(paths, args.web_port)           # prints the URL, returns only by Ctrl-C or SIGTERM
"""
from __future__ import annotations

import argparse
import ctypes
import os
import pathlib
import shutil
import socket
import signal
import subprocess
import sys
import tempfile
import time
import urllib.parse

from robostrich_suite import cli as cli_lib

HOST = "127.0.0.1"
DEFAULT_PORT = 9090  # the port Rerun's own web viewer uses
PR_SET_PDEATHSIG = 1  # prctl(2): the signal a child gets when its parent ends
START_TIMEOUT = 60.0  # s for the servers to listen: the rerun program is large and the machine may be busy


def add_flags(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--web", action="store_true",
                        help=f"then serve the .rrd recordings in Rerun's web viewer at http://{HOST}:PORT "
                             "until Ctrl-C (no display or native viewer needed)")
    parser.add_argument("--web-port", type=cli_lib.whole_number(1, 65534), default=DEFAULT_PORT, metavar="PORT",
                        help=f"port of the web viewer's page with --web (default {DEFAULT_PORT}); the recordings' "
                             "gRPC server takes PORT+1")


def check(args: argparse.Namespace) -> None:
    """Before any work, with --web: the recordings are written, the rerun program is there and the port is free
    (ValueError, one line, otherwise)."""
    if not args.web:
        return
    if getattr(args, "no_rerun", False):
        raise ValueError("--web serves the .rrd recordings, which --no-rerun turns off: drop one of them")
    rerun_program()
    check_ports(args.web_port)


def rerun_program() -> str:
    """The ``rerun`` program of rerun-sdk (rerun_cli), else one on PATH."""
    try:
        import rerun_cli
        bundled = pathlib.Path(rerun_cli.__file__).parent / "rerun"
        if bundled.is_file():
            return str(bundled)
    except ImportError:
        pass
    found = shutil.which("rerun")
    if found is None:
        raise ValueError("--web needs the rerun program of rerun-sdk, which is not installed (pip install -e .)")
    return found


def check_ports(web_port: int) -> None:
    """ValueError naming --web-port if something listens on HOST:web_port or on the gRPC port after it
    (each bound as the server will bind it)."""
    for port, what in ((web_port, ""), (web_port + 1, " (PORT+1, the recordings' gRPC server)")):
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
            probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                probe.bind((HOST, port))
            except OSError as error:
                raise ValueError(f"--web-port {web_port}: {HOST}:{port}{what} is taken ({error.strerror}); "
                                 "choose another port with --web-port") from None


def viewer_url(web_port: int, grpc_port: int) -> str:
    """The page, told where the recordings are (the viewer's ``url`` parameter)."""
    source = urllib.parse.quote(f"rerun+http://{HOST}:{grpc_port}/proxy", safe="")
    return f"http://{HOST}:{web_port}/?url={source}"


def _listening(port: int) -> bool:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.settimeout(0.5)
        return probe.connect_ex((HOST, port)) == 0


def _last_line(log) -> str:
    log.seek(0)
    lines = [line.strip() for line in log.read().decode(errors="replace").splitlines() if line.strip()]
    return lines[-1] if lines else "no output"


def _wait_until_listening(process: subprocess.Popen, ports, log) -> None:
    deadline = time.monotonic() + START_TIMEOUT
    while not all(_listening(port) for port in ports):
        if process.poll() is not None:
            raise ValueError(f"the web viewer did not start (rerun exited with {process.returncode}): {_last_line(log)}")
        if time.monotonic() > deadline:
            raise ValueError(f"the web viewer did not listen on {HOST}:{ports[0]} within {START_TIMEOUT:.0f} s")
        time.sleep(0.1)


def serve(paths, web_port: int, out=sys.stdout) -> None:
    """Serve the recordings ``paths`` until Ctrl-C or SIGTERM (a KeyboardInterrupt, re-raised once the
    servers are stopped); ValueError (one line) if they cannot start or stop on their own."""
    paths = [str(p) for p in paths]
    if not paths:
        raise ValueError("--web has no recording to serve")
    check_ports(web_port)  # again: the command's work took a while
    grpc_port = web_port + 1
    command = [rerun_program(), "--serve-web", "--bind", HOST, "--web-viewer-port", str(web_port),
               "--port", str(grpc_port), *paths]
    with tempfile.TemporaryFile() as log:
        process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                   env={**os.environ, "RUST_LOG": "warn"}, preexec_fn=_ended_with_this_process())
        try:
            _wait_until_listening(process, (web_port, grpc_port), log)
            print(f"serving {len(paths)} recording{'s' * (len(paths) > 1)} in Rerun's web viewer: "
                  f"{viewer_url(web_port, grpc_port)}  (Ctrl-C stops it)", file=out, flush=True)
            returncode = process.wait()
            raise ValueError(f"the web viewer stopped (rerun exited with {returncode}): {_last_line(log)}")
        finally:
            _stop(process)


def _ended_with_this_process():
    """For Popen's preexec_fn: on Linux the server gets SIGTERM when this process ends, however it
    ends (SIGKILL too, which runs no cleanup here), instead of listening on with no one to stop it;
    None elsewhere. prctl is looked up before the fork, so the child only calls it."""
    if not sys.platform.startswith("linux"):
        return None
    prctl, parent = ctypes.CDLL(None, use_errno=True).prctl, os.getpid()

    def in_child():
        prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
        if os.getppid() != parent:  # this process ended before the call: the signal will not come
            os._exit(1)
    return in_child


def _stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
