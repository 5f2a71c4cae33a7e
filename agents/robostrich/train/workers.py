"""robostrich-train's supervisor: each run (and the lookup's evaluation) in a process of its own,
their progress forwarded to the parent's bars, Ctrl-C and a run's error passed on to the others."""
import multiprocessing
import os
import queue as queue_lib
import signal

from agents.robostrich.evaluate import evaluation
from agents.robostrich.train.jobs import LookupSpec, PendingRun, RunJob, train_and_evaluate
from agents.robostrich.train.progress import QueueProgress
from robostrich_suite import cli as cli_lib


def _worker(spec: PendingRun, job, queue):
    """One run in its own process: restore its latest checkpoint (if any), train, evaluate.
    Ctrl-C (the terminal's, or the parent's on another run's error) writes a checkpoint first."""
    label = spec.label
    signal.signal(signal.SIGINT, signal.default_int_handler)  # the parent started it ignored
    try:
        if isinstance(spec, LookupSpec):
            spec.evaluate(job, QueueProgress(queue, label))
            outcome = {}
        else:
            run = spec.build(restore=True)
            queue.put(("resumed", label, run.loop.env_steps))  # where a resumed run starts
            outcome = train_and_evaluate(run, job, QueueProgress(queue, label))
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # done: a late request to stop changes nothing
        queue.put(("done", label, {k: v for k, v in outcome.items() if k != "reports"}))
    except KeyboardInterrupt as error:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent asks again until it hears this
        queue.put(("interrupted", label, str(error)))
    except (ValueError, OSError) as error:  # a user error: the parent's one line says it all
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # nor a traceback of the parent's later asks
        queue.put(("user_error", label, cli_lib.error_message(error)))
    except BaseException as error:  # a bug: its traceback follows, the parent names the run
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        queue.put(("error", label, f"{type(error).__name__}: {error}"))
        raise


def train_in_parallel(specs: dict, job: RunJob, progress, workers: int) -> dict:
    """Each run in its own process (one core each): the curriculum and the plain-SAC baseline are
    independent, so on two cores the main job takes the time of one run. Workers restore from and
    write the same checkpoints as a sequential run, so results are identical and resumable."""
    context = multiprocessing.get_context("spawn")
    queue = context.Queue()
    # One intra-op thread per worker; set before the spawned interpreters import JAX.
    saved = os.environ.get("XLA_FLAGS")
    os.environ["XLA_FLAGS"] = ((saved or "") + " --xla_cpu_multi_thread_eigen=false"
                               " intra_op_parallelism_threads=1").strip()
    active = {}
    ends = {"done": {}, "error": {}, "user_error": {}, "interrupted": {}}  # how each run ended
    with cli_lib.deferred_interrupts():
        try:
            _supervise(context, specs, job, progress, workers, queue, active, ends)
        finally:
            for process in active.values():
                process.terminate()
            if saved is None:
                os.environ.pop("XLA_FLAGS", None)
            else:
                os.environ["XLA_FLAGS"] = saved
    for kind, error in (("error", RuntimeError), ("user_error", ValueError)):
        if ends[kind]:
            raise error("; ".join(f"{label}: {message}" for label, message in ends[kind].items()))
    if ends["interrupted"]:
        raise KeyboardInterrupt(_stopped_workers(ends["interrupted"]))
    outcomes = ends["done"]
    for label, outcome in outcomes.items():
        outcome["reports"] = evaluation.read_reports(job.out_eval, label)
    return outcomes


def _stopped_workers(stopped: dict) -> str:
    """The interrupt's message from the workers' (label -> message): the checkpoints they wrote
    first, 'checkpoint written at step N: PATH; at step M: PATH', as the command's line shows one."""
    written = cli_lib.CHECKPOINT_WRITTEN
    saved = [message[len(written):].strip() for message in stopped.values() if message.startswith(written)]
    others = [f"{label}: {message}" for label, message in stopped.items() if message and not message.startswith(written)]
    return "; ".join(([f"{written} " + "; ".join(saved)] if saved else []) + others)


def _supervise(context, specs, job, progress, workers, queue, active, ends):
    """Start workers, forward their progress and collect how each ended (``ends``). On Ctrl-C or
    a run's error no run is started, and the running ones are asked (SIGINT, once a second until
    they answer) to write a checkpoint and stop."""
    pending = list(specs)
    while pending or active:
        stopping = cli_lib.interrupted() or ends["error"] or ends["user_error"]
        if stopping:
            pending.clear()
            for process in active.values():
                if process.is_alive():
                    os.kill(process.pid, signal.SIGINT)
        while pending and len(active) < workers:
            label = pending.pop(0)
            # the worker builds the run from the same seed, or restores it; it starts with Ctrl-C
            # ignored (a KeyboardInterrupt while it imports would print a traceback) and takes it
            # up in _worker
            ignored = signal.signal(signal.SIGINT, signal.SIG_IGN)
            try:
                process = context.Process(target=_worker, args=(specs[label], job, queue))
                process.start()
            finally:
                signal.signal(signal.SIGINT, ignored)
            active[label] = process
        try:
            kind, label, payload = queue.get(timeout=1.0)
        except queue_lib.Empty:  # check for workers that died without a word
            for label, process in list(active.items()):
                if not process.is_alive():
                    ends["interrupted" if stopping else "error"].setdefault(
                        label, f"worker exited with status {process.exitcode}")
                    del active[label]
            continue
        if kind == "steps":
            progress.advance(payload[0], label, payload[1])
        elif kind == "episode":
            progress.on_episode(payload)
        elif kind == "evaluated":
            progress.evaluated(payload)
        elif kind == "periodic":
            progress.periodic(label, payload)
        elif kind == "resumed":
            progress.skip(payload)
        elif label in active:  # the first word on how it ended
            ends[kind][label] = payload
            active.pop(label).join()
