"""robostrich-train's run directory: its lock, and the checks of a fresh run, a resume and a
finished run against what is already there, before anything is built or written."""
import json
import os
from typing import Optional

from agents import checkpoint
from agents.curriculum import read_records, run_files
from agents.robostrich import directory_lock
from agents.robostrich.train import transfer
from agents.robostrich.run_spec import migrate
from agents.robostrich.train.checks import TrainingSetup
from robostrich_suite import parsing


def lock_run_directory(out: str):
    """Make ``out`` this run's (agents/robostrich/directory_lock.py), held while the returned file
    stays open."""
    return directory_lock.lock_directory(out, "robostrich-train")


def previous_init_path(out: str) -> Optional[str]:
    """The --init-from path config.json recorded when this run started (a --resume may leave it out)."""
    try:
        with open(os.path.join(out, "config.json")) as f:
            return (json.load(f).get("init_from") or {}).get("path")
    except (OSError, ValueError):
        return None


def check_run_directory(args, setup: TrainingSetup) -> dict:
    """Refuse a fresh run over checkpoints, a resume of nothing, and a resume of another
    configuration or a damaged file, before anything is built or written; returns the
    curriculum's --init-from (path and content hash), if any."""
    existing = [l for l in setup.run_plans if os.path.exists(os.path.join(args.out, l, checkpoint.FILE_NAME))]
    pickled = [os.path.join(l, checkpoint.PICKLED_FILE_NAME) for l in setup.run_plans
               if os.path.exists(os.path.join(args.out, l, checkpoint.PICKLED_FILE_NAME))]
    if pickled and not existing:  # neither resumed nor trained over: its checkpoints are another format's
        raise ValueError(f"{args.out} holds checkpoints written with pickle by an earlier version ({', '.join(pickled)}), "
                         "which this version does not read; train again in another --out")
    if not args.resume and existing:
        raise ValueError(f"{args.out} already holds checkpoints ({', '.join(existing)}); "
                         "pass --resume to continue them or choose another --out")
    if args.resume and not existing:  # a typo in --out must not quietly start the whole job afresh
        looked = ", ".join(os.path.join(l, checkpoint.FILE_NAME) for l in setup.run_plans)
        where = (f"{args.out} holds no checkpoint ({looked})" if os.path.isdir(args.out)
                 else f"{args.out} does not exist")
        raise FileNotFoundError(f"--resume: nothing to resume: {where}; check --out, or leave out --resume "
                                "to start a fresh run")
    init = {}
    if args.init_from is not None:
        source = transfer.check_source(args.init_from, setup.plan, setup.config, args.layout,
                                       residual_scale=setup.residual_scale)
        init = {"init_from": source.path, "init_digest": source.digest}
    for label in existing if args.resume else ():
        init = _check_resumed(args, setup, label, init)
    return init


def _check_resumed(args, setup: TrainingSetup, label: str, init: dict) -> dict:
    """One run's checkpoint against this command line (and its records' lines); the --init-from
    a started curriculum recorded."""
    path = os.path.join(args.out, label, checkpoint.FILE_NAME)
    stored = migrate(checkpoint.read_fingerprint(path))
    if label == "curriculum":  # a started run's learner is in its checkpoint: --init-from may be left out
        if init and stored.get("init_from") != init["init_digest"]:
            raise ValueError(f"{path} did not start from --init-from {args.init_from} "
                             + ("(nor from any checkpoint)" if "init_from" not in stored else
                                "(it started from another checkpoint, or that file has changed since)"))
        init = {**init, "init_digest": stored["init_from"]} if "init_from" in stored else {}
    expected = setup.run_spec(args, label, init.get("init_digest") if label == "curriculum" else None).identity()
    checkpoint.check_fingerprint({k: stored.get(k, "<missing>") for k in expected}, expected, path)
    for records in run_files(os.path.join(args.out, label))[1:]:
        read_records(records)  # a damaged line other than a torn last one, named
    return init


def finished_summary(args, setup: TrainingSetup) -> Optional[dict]:
    """On --resume, the summary.json of a run whose every run has trained its whole plan; else None."""
    path = os.path.join(args.out, "summary.json")
    if not args.resume or not os.path.exists(path):
        return None
    summary = parsing.read_json(path)
    planned = {label: sum(l.steps for l in plan) for label, plan in setup.run_plans.items()}
    return summary if summary.get("env_steps") == planned else None
