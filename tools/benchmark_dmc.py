"""This SAC on standard dm_control tasks, against published state-SAC returns: is the agent itself sound?

    python tools/benchmark_dmc.py [--tasks reacher/easy,cartpole/swingup] [--seeds 0] [--steps N]
                                  [--eval-at 100000,200000] [--out runs/dmc]

Benchmark settings as published for state SAC on DMC (PlaNet's action repeats: reacher 4,
cartpole 8; budgets and evaluation points in environment (control) steps; 10 deterministic
evaluation episodes).  Default budgets: reacher/easy 200k, cartpole/swingup 100k.  Results go
to OUT/dmc.json (after every evaluation, so a killed run keeps what it measured; a results record's
input, tools/results_page.py add) and OUT/dmc.md.
"""
import argparse
import json
import os
import sys
import time
from collections import deque
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import RunSpec, parse_plan
from agents.robostrich.evaluate import episodes
from agents.robostrich.train.main_job import MAIN_JOB_SAC  # robostrich-train's agent, these flags on top
from agents.sac.builder import SACBuilder
from robostrich_suite.atomic_files import write_text  # the project's one atomic writer

# PlaNet's action repeats, used by the state-SAC baselines of CURL/DrQ; budgets are this tool's defaults.
ACTION_REPEAT = {"reacher/easy": 4, "cartpole/swingup": 8, "cheetah/run": 4, "finger/spin": 2,
                 "walker/walk": 2, "ball_in_cup/catch": 4}
DEFAULT_STEPS = {"reacher/easy": 200_000, "cartpole/swingup": 100_000}
# Published state-SAC evaluation returns (approximate; the "State SAC" column of CURL, Srinivas et al. 2020).
REFERENCE = {"reacher/easy": {100_000: 750, 500_000: 920}, "cartpole/swingup": {100_000: 835}}
REFERENCE_SOURCE = "published state SAC (CURL, Srinivas et al. 2020, Table 1), approximate"


def _ints(text: str, what: str):
    try:
        values = [int(float(s)) for s in text.split(",") if s.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{what} wants comma-separated integers, got {text!r}") from None
    if not values:
        raise argparse.ArgumentTypeError(f"{what} is empty")
    return values


def build_parser():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    p.add_argument("--tasks", default="reacher/easy,cartpole/swingup", help="comma-separated domain/task")
    p.add_argument("--seeds", type=lambda s: _ints(s, "--seeds"), default=[0], help="comma-separated (default 0)")
    p.add_argument("--steps", type=int, default=None,
                   help="control steps per task (default: reacher/easy 200000, cartpole/swingup 100000)")
    p.add_argument("--eval-at", type=lambda s: _ints(s, "--eval-at"), default=[100_000, 200_000],
                   help="evaluation points (control steps); those beyond a task's budget are dropped")
    p.add_argument("--eval-episodes", type=int, default=10, help="deterministic episodes per evaluation")
    p.add_argument("--action-repeat", type=int, default=None, help="override the published action repeat")
    p.add_argument("--out", default="runs/dmc", help="writes dmc.json, dmc.md and one directory per run")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    g = p.add_argument_group("SAC")
    g.add_argument("--hidden-sizes", default="256,256", help="comma-separated hidden layer sizes (default: %(default)s)")
    g.add_argument("--batch-size", type=int, default=256, help="transitions per update (default: %(default)s)")
    # A critic that learns fast: lr 1e-3, layer-normalised critics, two updates per transition
    # (Acme's 3e-4, no normalisation and one update reached 445 on reacher/easy at 100k, this 907;
    # docs/log/learning.md#the-learner-on-dm_control-2026-11-30-and-2026-12-01).
    g.add_argument("--learning-rate", type=float, default=1e-3,
                   help="of critics, actor and temperature (default: %(default)s)")
    g.add_argument("--critic-layer-norm", action=argparse.BooleanOptionalAction, default=True,
                   help="layer-normalised critics (default: on)")
    g.add_argument("--updates-per-call", type=int, default=16, help="gradient steps per learner call (default: "
                   "%(default)s, two per transition with --env-steps-per-call 8)")
    g.add_argument("--env-steps-per-call", type=int, default=8, help="agent steps (transitions) between learner calls")
    g.add_argument("--min-replay-size", type=int, default=5000, help="transitions (agent steps) of uniform actions first")
    g.add_argument("--init-temperature", type=float, default=0.01,
                   help="initial entropy temperature (Acme: 1; default: the arm agent's %(default)s)")
    g.add_argument("--target-entropy-per-action", type=float, default=-1.0,
                   help="target entropy per action dimension (default: Acme's %(default)s)")
    g.add_argument("--pre-tanh-penalty", type=float, default=0.0,
                   help="penalty on the policy's squared pre-tanh mean (default: %(default)s; the arm's "
                        "default 0.1 is its remedy for a saturated tendon, not measured on these tasks)")
    return p


def task_settings(args, task: str):
    """(budget, action repeat, evaluation points) of one task; ValueError names what is missing."""
    from dm_control import suite
    if tuple(task.split("/")) not in suite.ALL_TASKS:
        raise ValueError(f"{task!r} is not a dm_control suite domain/task (e.g. cartpole/swingup)")
    steps = args.steps if args.steps is not None else DEFAULT_STEPS.get(task)
    if steps is None:
        raise ValueError(f"no default budget for {task}; pass --steps")
    repeat = args.action_repeat or ACTION_REPEAT.get(task)
    if repeat is None:
        raise ValueError(f"no published action repeat for {task}; pass --action-repeat")
    eval_at = sorted({s for s in args.eval_at if 0 < s <= steps}) or [steps]
    return steps, repeat, eval_at


def reference_at(task: str, step: int):
    return REFERENCE.get(task, {}).get(step)


class Progress:
    """tqdm over all control steps of all runs, with the run and its recent training return."""

    def __init__(self, total: int, enabled: bool):
        from tqdm import tqdm
        self.bar = tqdm(total=total, unit="step", dynamic_ncols=True, smoothing=0.05, disable=not enabled)
        self.returns = deque(maxlen=10)
        self.label = ""

    def on_episode(self, record):
        self.returns.append(record["return"])

    def update(self, n, run):
        self.bar.update(n)
        ret = sum(self.returns) / len(self.returns) if self.returns else float("nan")
        self.bar.set_postfix(run=self.label, ret=f"{ret:.0f}", refresh=False)

    def start(self, label):
        self.label = label
        self.returns.clear()


def format_table(rows) -> str:
    """Markdown: deterministic evaluation return per task, seed and step, beside the published one."""
    lines = ["| task | seed | control steps | return (mean ± std) | episodes | published state SAC |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        ref = "-" if r["reference"] is None else f"~{r['reference']}"
        lines.append(f"| {r['task']} | {r['seed']} | {r['eval_step']} | "
                     f"{r['return_mean']:.1f} ± {r['return_std']:.1f} | {r['episodes']} | {ref} |")
    seeds = sorted({r["seed"] for r in rows})
    if len(seeds) > 1:
        lines += ["", "| task | control steps | mean over seeds [min, max] | seeds |", "|---|---|---|---|"]
        for key in sorted({(r["task"], r["eval_step"]) for r in rows}):
            means = [r["return_mean"] for r in rows if (r["task"], r["eval_step"]) == key]
            lines.append(f"| {key[0]} | {key[1]} | {sum(means) / len(means):.1f} [{min(means):.1f}, {max(means):.1f}] "
                         f"| {len(means)} |")
    refs = "; ".join(f"{t}: " + ", ".join(f"~{v} at {s // 1000}k" for s, v in sorted(r.items()))
                     for t, r in REFERENCE.items())
    return "\n".join(lines + ["", f"Reference ({REFERENCE_SOURCE}): {refs}."]) + "\n"


def write_atomic(path: str, text: str) -> None:
    write_text(path, text)


def train_and_evaluate(task, seed, steps, eval_at, config, args, progress, on_row):
    """One SAC run on `task`; `on_row(row)` after each deterministic evaluation."""
    domain, task_name = task.split("/")
    run_dir = os.path.join(args.out, task.replace("/", "_"), f"seed_{seed}")
    run = DomainRun(RunSpec(parse_plan(f"{task}:{steps}"), config, seed), run_dir, checkpoint_every=steps, name=task)
    for path in (run.metrics_path, run.evals_path):  # a fresh run: no records of an earlier one
        if os.path.exists(path):
            os.unlink(path)
    pending = list(eval_at)
    start = time.time()

    def on_eval(r):
        while pending and pending[0] <= r.loop.env_steps:
            step = pending.pop(0)
            actor = SACBuilder.make_eval_actor(r.loop)
            report = episodes.evaluate_heldout(actor, r.loop.flattener, r.domain(), task_name, None,
                                               args.eval_episodes, action_repeat=config.action_repeat)
            s = report["summary"]
            on_row({"task": task, "seed": seed, "eval_step": step, "env_steps": r.loop.env_steps,
                    "return_mean": s["return_mean"], "return_std": s["return_std"],
                    "return_min": s["return_min"], "return_max": s["return_max"], "episodes": s["episodes"],
                    "reference": reference_at(task, step), "action_repeat": config.action_repeat,
                    "updates": r.loop.learner.num_updates, "minutes": (time.time() - start) / 60.0})

    progress.start(f"{task} seed {seed}")
    run.run(progress=progress, on_eval=on_eval, eval_at=eval_at)


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    tasks = [t.strip() for t in args.tasks.split(",") if t.strip()]
    try:
        if not tasks:
            raise ValueError("--tasks is empty")
        if args.eval_episodes <= 0:
            raise ValueError("--eval-episodes must be positive")
        settings = {t: task_settings(args, t) for t in tasks}
        import dataclasses
        configs = {t: dataclasses.replace(MAIN_JOB_SAC, batch_size=args.batch_size, learning_rate=args.learning_rate,
                                          hidden_sizes=tuple(int(h) for h in args.hidden_sizes.split(",") if h),
                                          min_replay_size=args.min_replay_size, updates_per_call=args.updates_per_call,
                                          env_steps_per_call=args.env_steps_per_call, action_repeat=settings[t][1],
                                          critic_layer_norm=args.critic_layer_norm, init_temperature=args.init_temperature,
                                          target_entropy_per_action=args.target_entropy_per_action,
                                          pre_tanh_penalty=args.pre_tanh_penalty,
                                          her_ratio=0.0) for t in tasks}
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    os.makedirs(args.out, exist_ok=True)
    rows = []
    command = ["python", "tools/benchmark_dmc.py", *(sys.argv[1:] if argv is None else argv)]
    result = {"benchmark": "dmc", "command": command, "arguments": vars(args), "configs": {t: c.to_dict() for t, c in configs.items()},
              "reference": {t: {str(s): v for s, v in r.items()} for t, r in REFERENCE.items()},
              "reference_source": REFERENCE_SOURCE, "rows": rows}

    def on_row(row):
        rows.append(row)
        progress.bar.write(f"{row['task']} seed {row['seed']} at {row['eval_step']} steps: return "
                           f"{row['return_mean']:.1f} ± {row['return_std']:.1f} (reference "
                           f"{'-' if row['reference'] is None else '~%d' % row['reference']})")
        write_atomic(os.path.join(args.out, "dmc.json"), json.dumps(result, indent=1))

    progress = Progress(sum(settings[t][0] for t in tasks) * len(args.seeds), enabled=not args.quiet)
    try:
        for task in tasks:
            steps, _, eval_at = settings[task]
            for seed in args.seeds:
                train_and_evaluate(task, seed, steps, eval_at, configs[task], args, progress, on_row)
    finally:
        progress.bar.close()
    table = format_table(rows)
    write_atomic(os.path.join(args.out, "dmc.json"), json.dumps(result, indent=1))
    write_atomic(os.path.join(args.out, "dmc.md"), table)
    print(table)
    print(f"wrote {os.path.join(args.out, 'dmc.md')} and dmc.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
