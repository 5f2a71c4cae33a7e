"""Starts one sweep run's robostrich-train so that whatever ends the Ray worker, the run ends as by
SIGTERM: it writes its checkpoint, then exits.

    python run_launcher.py WORKER_PID COMMAND [ARGS...]     (run by sweep_ray.train_run)

Ray's worker may SIGKILL its child processes and their process group when it exits (its driver
killed, a node lost), which would stop a run without a checkpoint. So this launcher stands
between them: it starts the command as its own child, detached by setsid() from the worker's process group, out of reach of
those kills, and asks the kernel (PR_SET_PDEATHSIG) to send the command SIGTERM when the launcher
dies, and the launcher SIGTERM when the worker dies. Ctrl-C or SIGTERM sent to the launcher (a
cancelled task) is passed on; the launcher exits with the command's status (128 + N for signal N).
Ray's workers block SIGINT, and a child inherits the mask: both processes unblock it.
Standard library only, and run by path: it starts before anything of the project is imported.
"""
import ctypes
import os
import signal
import sys

PR_SET_PDEATHSIG = 1
FORWARDED = (signal.SIGINT, signal.SIGTERM)


def _die_with_parent(expected_parent: int) -> None:
    """SIGTERM to this process when its parent dies; exit 137 if it already has."""
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    if os.getppid() != expected_parent:
        os._exit(137)


def main(argv: list) -> int:
    worker, command = int(argv[0]), argv[1:]
    pending = []  # a stop that came before the command had started
    for signum in FORWARDED:
        signal.signal(signum, lambda signum, frame: pending.append(signum))
    signal.pthread_sigmask(signal.SIG_UNBLOCK, set(FORWARDED))
    _die_with_parent(worker)
    launcher = os.getpid()
    child = os.fork()
    if child == 0:
        try:
            os.setsid()
            for signum in FORWARDED:
                signal.signal(signum, signal.SIG_DFL)
            _die_with_parent(launcher)
            os.execv(command[0], command)
        finally:
            os._exit(127)

    def forward(signum, frame):
        os.kill(child, signum)
    for signum in FORWARDED:
        signal.signal(signum, forward)
    for signum in pending:
        os.kill(child, signum)
    _, status = os.waitpid(child, 0)  # retried after each forwarded signal (PEP 475)
    code = os.waitstatus_to_exitcode(status)
    return code if code >= 0 else 128 - code


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
