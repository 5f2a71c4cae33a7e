"""Tables of a "peers" results record: SBX's SAC, TQC and CrossQ beside our curriculum SAC, our plain
SAC and the lookup on the arm, at one budget and seeds (tools/benchmark_peers.py's peers.json)."""
from results_seeds import cell

KINDS = {"heldout": "held-out, fixed start", "heldout_moving": "moving starts", "track": "`track`"}


def read(data: dict, path: str) -> tuple:
    """(data, the command it records); runs and seeds are required."""
    if not data.get("runs") or not data.get("seeds"):
        raise ValueError(f"{path} holds no run of tools/benchmark_peers.py (no 'runs' or 'seeds')")
    return data, data.get("command")


def caption(data: dict) -> str:
    versions = ", ".join(f"{k} {v}" for k, v in data.get("versions", {}).items())
    ways = "; ".join(f"{way}: {plan}" for way, plan in data.get("ways", {}).items())
    unfinished = f" (not finished: {'; '.join(data['unfinished'])})" if data.get("unfinished") else ""
    return (f"{data['steps']} control steps per run, mean [min, max] over seeds {', '.join(map(str, data['seeds']))}"
            f"{unfinished}; "
            f"peers with their published defaults ({versions}); lessons as run ({ways}); steps to "
            f"{data['bar'] * 100:.0f} %: the first evaluation point where the seeds' mean held-out success "
            f"(fixed start, {data['num_eval_targets']} targets) reaches it")


def _reach(run: dict) -> str:
    return f"{run['reach_bar'] // 1000}k" if run["reach_bar"] is not None and run["reach_bar"] % 1000 == 0 \
        else str(run["reach_bar"] or "not reached")


def _partial(run: dict, data: dict) -> str:
    """' (seed 0 of 0, 1)' for a run finished on fewer seeds than the command's, else ''."""
    seeds = run.get("seeds", data["seeds"])
    return f" (seed {', '.join(map(str, seeds))} of seeds {', '.join(map(str, data['seeds']))})" if seeds != data["seeds"] else ""


def _lookup_row(data: dict, kinds: list, detail: bool) -> str:
    lookup = data.get("lookup", {})
    cells = [f"{lookup[k]['success_rate'] * 100:.1f} %" if k in lookup else "-" for k in kinds]
    fixed = lookup.get("heldout")
    extra = ([f"{fixed['precise_success_rate'] * 100:.1f} %", f"{fixed['position_error_median'] * 100:.2f} cm, "
              f"{fixed['attitude_error_median']:.2f} deg"] if fixed else ["-", "-"]) if detail else []
    return "| lookup (no learning) | " + " | ".join(cells + extra + ["-", "-"]) + " |"


def short(data: dict) -> list:
    """One row per run: success of each evaluation, the precise share and median errors from the fixed
    start, steps to the bar, minutes per run."""
    kinds = [k for k in KINDS if any(k in run["final"] for run in data["runs"].values())]
    lines = ["| run | " + " | ".join(KINDS[k] for k in kinds)
             + " | within 1 cm and 2 deg | median error | steps to the bar | minutes per run |",
             "|---|" + "---|" * (len(kinds) + 4)]
    for run in data["runs"].values():
        final = run["final"]
        cells = [cell(final[k]["success_rate"], 100, "%") if k in final else "-" for k in kinds]
        fixed = final.get("heldout")
        cells += [cell(fixed["precise_success_rate"], 100, "%"),
                  f"{fixed['position_error_median']['mean'] * 100:.2f} cm, "
                  f"{fixed['attitude_error_median']['mean']:.2f} deg"] if fixed else ["-", "-"]
        cells += [_reach(run), cell(run["minutes"], 1, "min")]
        lines.append(f"| {run['name']}{_partial(run, data)} | " + " | ".join(cells) + " |")
    return lines + [_lookup_row(data, kinds, detail=True)]


def full(data: dict) -> list:
    """The short table, then every run's per-seed success from the fixed start."""
    lines = short(data) + [""]
    for run in data["runs"].values():
        values = run["final"].get("heldout", {}).get("success_rate", {}).get("values", [])
        seeds = ", ".join(f"seed {s}: {v * 100:.1f} %" if v is not None else f"seed {s}: -"
                          for s, v in zip(run.get("seeds", data["seeds"]), values))
        lines.append(f"- {run['name']}: held-out from the fixed start {seeds}")
    return lines
