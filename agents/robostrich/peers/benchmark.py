"""Every agent of the peers' comparison as one list of jobs, run one per core, summed into peers.json.

Why one command: a ratio such as "our curriculum reaches 95 % in X steps, the best peer in Y"
means something only when both come from the same run on the same machine, budget and seeds.
Our curriculum SAC and plain SAC are robostrich-train runs (the main job's defaults, at this
budget); the lookup is evaluated once; the peers are agents/robostrich/peers/sbx_agents.py.
"""
import contextlib
import dataclasses
import json
import os
import shutil
from typing import Optional

from agents.curriculum import Lesson, read_records
from agents.robostrich.train import main_job
from agents.robostrich.peers import sbx_agents as peers
from agents.robostrich.train import command as training
from agents.robostrich.domains import Domain
from robostrich_suite import atomic_files

DOMAIN = "robostrich"
OURS = {"curriculum": "curriculum SAC (ours)", "plain": "plain SAC (ours, final lesson only)"}
KINDS = ("heldout", "heldout_moving", "track")
FIELDS = ("success_rate", "precise_success_rate", "position_error_median", "attitude_error_median")
BAR = 0.95  # the held-out success whose first crossing the record compares


@dataclasses.dataclass(frozen=True)
class Settings:
    """The comparison's budget and evaluation, from the command line."""
    steps: int
    seeds: tuple
    agents: tuple  # "curriculum", "plain" and keys of peers.PEERS
    ways: tuple  # keys of peers.WAYS
    out: str
    eval_every: int
    num_eval_targets: int
    final_eval_targets: Optional[int]
    track_task: Optional[str]
    ours_args: tuple = ()  # robostrich-train flags our runs take besides the main job's
    task_kwargs: dict = dataclasses.field(default_factory=dict)  # every agent's, over the main job's


def lesson_plan(way: str, steps: int) -> tuple:
    """The main job's lessons and shares at ``steps`` ('lessons'), or its final lesson alone ('final')."""
    tasks = Domain(DOMAIN).curriculum()
    if way == "final":
        return (Lesson(DOMAIN, tasks[-1], steps),)
    shares = main_job.MAIN_JOB_LESSON_SHARES[DOMAIN]
    parts = [steps * share // sum(shares) for share in shares[:-1]]
    return tuple(Lesson(DOMAIN, t, s) for t, s in zip(tasks, parts + [steps - sum(parts)]))


def eval_points(settings: Settings) -> tuple:
    return tuple(range(settings.eval_every, settings.steps + 1, settings.eval_every)) + (settings.steps,)


def job_labels(settings: Settings) -> list:
    """Run labels in the record's order, our SAC first (run_all starts them longest first: START_ORDER)."""
    ours = [a for a in OURS if a in settings.agents]
    return ours + [f"{a}_{w}" for a in peers.PEERS if a in settings.agents for w in settings.ways]


def peer_spec(settings: Settings, label: str, seed: int) -> peers.PeerSpec:
    agent, way = label.rsplit("_", 1)
    domain = Domain(DOMAIN)
    return peers.PeerSpec(agent, way, seed, lesson_plan(way, settings.steps),
                          main_job.resolve_task_kwargs(settings.task_kwargs, domain), main_job.resolve_layout(None, domain),
                          domain.heldout_task("lesson3"), settings.track_task, eval_points(settings),
                          settings.num_eval_targets, settings.final_eval_targets, job_dir(settings, label, seed))


def ours_argv(settings: Settings, label: str, seed: int) -> list:
    """robostrich-train's command line for our run ``label`` at this budget (one process, no baseline)."""
    plan = lesson_plan("lessons" if label == "curriculum" else "final", settings.steps)
    argv = ["--plan", ",".join(f"{l.domain}/{l.task}:{l.steps}" for l in plan), "--seed", str(seed),
            "--no-baseline", "--workers", "1", "--out", job_dir(settings, label, seed), "--no-rerun",
            "--no-figures", "--quiet", "--eval-every", str(settings.eval_every),
            "--num-eval-targets", str(settings.num_eval_targets), "--track-task", settings.track_task or ""]
    if settings.final_eval_targets:
        argv += ["--final-eval-targets", str(settings.final_eval_targets)]
    if settings.task_kwargs:
        argv += ["--task-kwargs", json.dumps(settings.task_kwargs)]
    return argv + list(settings.ours_args)


def check_ours_args(ours_args: tuple) -> None:
    """ValueError naming the flag unless robostrich-train takes ``ours_args`` (checked before any run starts)."""
    parser = training.build_parser()

    def refuse(message):
        raise ValueError(f"--ours-args: robostrich-train says {' '.join(message.split())}")
    parser.error = refuse  # one line from the tool, not robostrich-train's usage and exit
    parser.parse_args(["--no-baseline", *ours_args])


def job_dir(settings: Settings, label: str, seed: int) -> str:
    return os.path.join(settings.out, "runs", label, f"seed_{seed}")


def compact(summary: dict) -> dict:
    return {field: summary.get(field) for field in FIELDS}


def run_ours(settings: Settings, label: str, seed: int) -> dict:
    """Our run through robostrich-train (its lookup evaluation too); its result as a peer's."""
    out = job_dir(settings, label, seed)
    with open(os.path.join(out, "train.log"), "w") as log, contextlib.redirect_stdout(log):
        summary = training.main(ours_argv(settings, label, seed))
    curve = read_records(os.path.join(out, "curriculum", "evals.jsonl"))
    return {"env_steps": summary["env_steps"]["curriculum"],
            "train_seconds": summary["timings"]["curriculum"]["seconds"],
            "curve": [{"env_steps": r["env_steps"], "summary": r["summary"]} for r in curve],
            "final": summary["runs"]["curriculum"], "lookup": summary["runs"].get("lookup")}


def run_job(settings: Settings, label: str, seed: int) -> dict:
    """One run in this process (a fresh worker's): trained afresh, its result written to OUT/.../result.json."""
    out = job_dir(settings, label, seed)
    shutil.rmtree(out, ignore_errors=True)  # an unfinished run starts again
    os.makedirs(out)
    result = run_ours(settings, label, seed) if label in OURS else peers.train(peer_spec(settings, label, seed))
    result["final"] = {kind: compact(s) for kind, s in result["final"].items()}
    result["curve"] = [[r["env_steps"], r["summary"]["success_rate"]] for r in result["curve"]]
    atomic_files.write_json(os.path.join(out, "result.json"), result)
    return result


def read_result(settings: Settings, label: str, seed: int) -> Optional[dict]:
    path = os.path.join(job_dir(settings, label, seed), "result.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


# The order runs start in, the longest first so that a pool of workers finishes soonest: a run of
# CrossQ (wide critics) takes longest, then TQC and SAC, and ours minutes where a peer takes tens.
START_ORDER = ("crossq", "tqc", "sac")


def _start_rank(job) -> int:
    agent = job[0].rsplit("_", 1)[0]
    return START_ORDER.index(agent) if agent in START_ORDER else len(START_ORDER)


def run_all(settings: Settings, workers: int, say=print, train: bool = True) -> dict:
    """Every (run, seed) not finished yet, ``workers`` at a time, each in a fresh single-threaded
    process (none with ``train`` False); {(label, seed): result, None where unfinished}."""
    import concurrent.futures
    import multiprocessing
    jobs = [(label, seed) for label in job_labels(settings) for seed in settings.seeds]
    results = {job: read_result(settings, *job) for job in jobs}
    todo = sorted((job for job in jobs if results[job] is None), key=_start_rank) if train else []
    if not todo:
        return results
    os.environ["XLA_FLAGS"] = ((os.environ.get("XLA_FLAGS") or "") + " --xla_cpu_multi_thread_eigen=false"
                               " intra_op_parallelism_threads=1").strip()  # read by the workers' JAX
    with concurrent.futures.ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"),
                                                max_tasks_per_child=1) as pool:
        futures = {pool.submit(run_job, settings, *job): job for job in todo}
        for future in concurrent.futures.as_completed(futures):
            label, seed = futures[future]
            results[(label, seed)] = future.result()
            say(f"{label} seed {seed}: done ({results[(label, seed)]['train_seconds'] / 60:.1f} min)")
    return results
