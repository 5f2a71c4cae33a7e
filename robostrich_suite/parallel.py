"""Work split over processes that Ctrl-C stops at once: the workers ignore the terminal's
interrupt and the parent, which has the command's one line to print, ends them (a pool left to
finish its work would hold the command for as long as the draw lasts, and workers interrupted
with it would each print a traceback). One progress bar, drawn by the parent, follows the items
the workers count (``count``).

One plain process per job, not multiprocessing.Pool: Pool.terminate() can wait forever for a lock
an idle worker holds while it waits for a task."""
from __future__ import annotations

import multiprocessing
import pickle
import queue as queue_lib
import signal
import traceback

from robostrich_suite import cli

STOP_SIGNALS = {signal.SIGINT, signal.SIGTERM}
_counted = None  # in a worker: the shared count of finished items


def count(items: int = 1) -> None:
    """In a worker of ``map_processes``: ``items`` more are done (the parent's bar advances)."""
    if _counted is not None:
        with _counted.get_lock():
            _counted.value += items


def map_processes(function, jobs: list, bar=None) -> list:
    """``[function(job) for job in jobs]``, one process per job; ``bar`` (a tqdm bar, or None)
    advances by what the workers ``count``. A worker's exception is raised here; on Ctrl-C or
    an error every worker is ended before the exception leaves."""
    context = multiprocessing.get_context()
    counted, results = context.Value("q", 0), context.Queue()
    processes = []
    try:
        _start(context, processes, [(function, index, job, results, counted) for index, job in enumerate(jobs)])
        values = _collect(processes, results, counted, bar)
    except BaseException:
        for process in processes:
            if process.is_alive():
                process.terminate()
        raise
    finally:
        for process in processes:
            process.join()
    return [values[index] for index in range(len(jobs))]


def _start(context, processes: list, arguments: list) -> None:
    """One worker per item of ``arguments``, each in ``processes`` as soon as it exists. A stop
    meanwhile waits until all are there (a Ctrl-C raised in Python's fork callbacks would be
    swallowed, and a worker the parent does not know of outlives it); the workers start with the
    stop signals blocked, and ignore SIGINT before they unblock them (so SIGTERM, terminate(),
    always ends one)."""
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
    try:
        with cli.deferred_interrupts():
            for args in arguments:
                processes.append(context.Process(target=_work, args=args, daemon=True))
                processes[-1].start()
            stopped = cli.interrupted()
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
    if stopped:
        raise KeyboardInterrupt


def _collect(processes: list, results, counted, bar) -> dict:
    values = {}
    while len(values) < len(processes):
        try:
            index, ok, value = results.get(timeout=0.25)
        except queue_lib.Empty:
            cli.raise_if_interrupted()  # a Ctrl-C some callback swallowed
            _show(bar, counted)
            died = [p.exitcode for p in processes if p.exitcode not in (None, 0)]
            if died:  # killed (out of memory, say) before it could say why
                raise RuntimeError(f"a worker process ended with status {died[0]}")
            continue
        if not ok:
            raise value
        values[index] = value
    _show(bar, counted)
    return values


def _work(function, index: int, job, results, counted) -> None:
    global _counted
    _counted = counted
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent decides; SIGTERM (its terminate()) ends it
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)
    try:
        results.put((index, True, function(job)))
    except Exception as error:  # raised in the parent; a bug keeps the worker's traceback as a note
        error.add_note("in a worker process:\n" + traceback.format_exc())
        try:
            pickle.dumps(error)
        except Exception:  # the queue would drop it, and the parent wait for ever
            error = RuntimeError(f"{type(error).__name__}: {error}\n" + traceback.format_exc())
        results.put((index, False, error))


def _show(bar, counted) -> None:
    if bar is not None and counted.value > bar.n:
        bar.update(counted.value - bar.n)
