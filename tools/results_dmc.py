"""Tables of a "dmc" results record: this SAC on dm_control tasks against published state-SAC
returns (tools/benchmark_dmc.py's dmc.json)."""
import shlex


def read(data: dict, path: str) -> tuple:
    """(data, the command it records or None); rows of (task, seed, evaluation point) are required."""
    if not data.get("rows"):
        raise ValueError(f"{path} holds no evaluation of tools/benchmark_dmc.py (no 'rows')")
    command = data.get("command")
    return data, (shlex.join(command) if isinstance(command, list) else command)


def _points(data: dict) -> list:
    return sorted({(r["task"], r["eval_step"]) for r in data["rows"]})


def caption(data: dict) -> str:
    rows = data["rows"]
    seeds = sorted({r["seed"] for r in rows})
    episodes = sorted({r["episodes"] for r in rows})
    repeats = sorted({f"{r['task']} {r['action_repeat']}" for r in rows})
    missing = [s for s in data.get("arguments", {}).get("seeds", []) if s not in seeds]
    unfinished = f" (seed {', '.join(map(str, missing))} of the command not finished)" if missing else ""
    return (f"deterministic evaluation return ({'/'.join(map(str, episodes))} episodes per seed and point), "
            f"mean [min, max] over seeds {', '.join(map(str, seeds))}{unfinished}; action repeats as published "
            f"({', '.join(repeats)})")


def full(data: dict) -> list:
    """One row per task and evaluation point: each seed's return, their mean [min, max], the published one."""
    seeds = sorted({r["seed"] for r in data["rows"]})
    lines = ["| task | control steps | " + " | ".join(f"seed {s}" for s in seeds)
             + " | mean [min, max] | published state SAC |",
             "|---|---|" + "---|" * (len(seeds) + 2)]
    for task, step in _points(data):
        rows = {r["seed"]: r for r in data["rows"] if (r["task"], r["eval_step"]) == (task, step)}
        means = [r["return_mean"] for r in rows.values()]
        reference = next(iter(rows.values()))["reference"]
        cells = [f"{rows[s]['return_mean']:.0f}" if s in rows else "-" for s in seeds]
        spread = f"**{sum(means) / len(means):.0f}** [{min(means):.0f}, {max(means):.0f}]"
        steps = f"{step // 1000}k" if step % 1000 == 0 else str(step)
        lines.append(f"| {task} | {steps} | " + " | ".join(cells) + f" | {spread} | "
                     + ("-" if reference is None else f"~{reference}") + " |")
    return lines + ["", f"Reference: {data.get('reference_source', 'see tools/benchmark_dmc.py')}."]


short = full
