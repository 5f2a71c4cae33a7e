"""Tables of a "seeds" results record: the main job over seeds (curriculum SAC, plain SAC and the
lookup), from one group of robostrich-sweep's sweep.json or an earlier benchmark_seeds.py seeds.json."""
import shlex

RUNS = {"curriculum": "curriculum SAC", "baseline": "plain SAC (final lesson only)", "lookup": "lookup (no learning)"}
KINDS = {"heldout": "held-out, fixed start", "heldout_moving": "held-out, moving starts",
         "new": "new targets, fixed start", "new_moving": "new targets, moving starts (one each)",
         "track": "`track` (3 targets in turn)"}
SHORT_KINDS = {"heldout": "held-out, fixed start", "heldout_moving": "moving starts", "new": "new targets",
               "new_moving": "new, moving starts", "track": "`track`"}
AFTER = "heldout_after_"  # the evaluation at the end of a lesson but the last


def read(data: dict, path: str, group: str = None) -> tuple:
    """(aggregate, the command it records or None) of a sweep.json (one group) or a seeds.json."""
    if "groups" in data and "command" in data:
        return sweep_group(data, path, group)
    if "results" not in data or "seeds" not in data:
        raise ValueError(f"{path} is not a tools/benchmark_seeds.py seeds.json nor a robostrich-sweep "
                         "sweep.json (no 'results'/'seeds', no 'groups'), nor names a benchmark this tool "
                         "records ('benchmark': dmc, layouts or speed)")
    if group is not None:
        raise ValueError(f"--group {group}: {path} is a seeds.json of one group")
    return data, None


def sweep_group(sweep: dict, path: str, group: str = None) -> tuple:
    """(aggregate, command) of one group of a robostrich-sweep sweep.json: ``group``, or its only one."""
    groups = sweep["groups"]
    if group is None and len(groups) != 1:
        raise ValueError(f"{path} holds groups {', '.join(groups)}: name one with --group")
    name = group if group is not None else next(iter(groups))
    if name not in groups:
        raise ValueError(f"{path} has no group {name!r} (it has {', '.join(groups)})")
    if groups[name]["aggregate"] is None:
        raise ValueError(f"{path}: group {name} has no finished run")
    return groups[name]["aggregate"], shlex.join(sweep["command"])


def kind_title(kind: str) -> str:
    if kind.startswith(AFTER):
        return f"held-out, fixed start, after {kind[len(AFTER):]}"
    return KINDS.get(kind, kind)


def cell(stats: dict, scale: float, unit: str, digits: int = 1) -> str:
    """'mean unit [min, max]', or 'mean unit' when every seed gave the same."""
    if stats["mean"] is None:
        return "-"
    mean, low, high = (f"{stats[k] * scale:.{digits}f}" for k in ("mean", "min", "max"))
    return f"{mean} {unit}" if low == high else f"{mean} {unit} [{low}, {high}]"


def partial_seeds(row: dict, seeds: int) -> str:
    """' (k of n seeds)' for a row evaluated on fewer seeds than its record has, else ''."""
    counted = row.get("seeds", seeds)
    return f" ({counted} of {seeds} seeds)" if counted != seeds else ""


def seeds_table(data: dict) -> list:
    """Markdown rows: every run and evaluation, mean [min, max] over the seeds."""
    lines = ["| run | evaluation | success | within 1 cm and 2 deg | median position error | median attitude error |",
             "|---|---|---|---|---|---|"]
    seeds = len(data["seeds"])
    for label, kinds in data["results"].items():
        for kind, row in kinds.items():
            lines.append(f"| {RUNS.get(label, label)} | {kind_title(kind)}{partial_seeds(row, seeds)} | "
                         f"{cell(row['success_rate'], 100, '%')} | {cell(row['precise_success_rate'], 100, '%')} | "
                         f"{cell(row['position_error_median'], 100, 'cm', 2)} | "
                         f"{cell(row['attitude_error_median'], 1, 'deg', 2)} |")
    return lines


def per_seed(data: dict) -> tuple:
    """(what the cells are, each seed's cells): the curriculum's success in every evaluation it has
    (`track` as targets reached of 3) and the wall-clock of the whole job."""
    curriculum = data["results"].get("curriculum", {})
    kinds = (["heldout", "heldout_moving"] + [k for k in ("new", "new_moving") if k in curriculum]
             + ["track"] * ("track" in curriculum) + sorted(k for k in curriculum if k.startswith(AFTER)))
    parts = []
    for i, seed in enumerate(data["seeds"]):
        cells = []
        for kind in kinds:
            values = curriculum.get(kind, {}).get("success_rate", {}).get("values", [])
            if kind == "track":
                cells.append(f"{round(values[i] * 3)} of 3 track targets" if i < len(values) else "-")
            else:
                cells.append(f"{values[i] * 100:.1f} %" if i < len(values) else "-")
        minutes = data["minutes"][i]
        cells.append(f"{minutes:.1f} min" if minutes is not None else "time unknown")
        parts.append(f"seed {seed}: " + " / ".join(cells))
    names = {"heldout": "held-out fixed", "heldout_moving": "moving", "new": "new fixed", "new_moving": "new moving",
             "track": "`track`"}
    header = " / ".join([names.get(k, f"after {k[len(AFTER):]}") for k in kinds] + ["wall-clock of the whole job"])
    return header, "; ".join(parts)


def budget(data: dict) -> str:
    """'curriculum SAC 600000, plain SAC ... 600000': the control steps each run trained."""
    return ", ".join(f"{RUNS.get(label, label)} {'/'.join(str(v) for v in sorted(set(filter(None, values))))}"
                     for label, values in data["steps"].items() if any(values))


def caption(data: dict) -> str:
    minutes = [m for m in data.get("minutes", []) if m is not None]
    spent = f"; wall-clock per seed {min(minutes):.1f}-{max(minutes):.1f} min" if minutes else ""
    return (f"mean [min, max] over seeds {', '.join(map(str, data['seeds']))}; "
            f"control steps per run: {budget(data)}{spent}")


def full(data: dict) -> list:
    """The page's lines: every row, then each seed's curriculum results."""
    header, seeds = per_seed(data)
    return seeds_table(data) + ["", f"Curriculum SAC per seed ({header}): {seeds}."]


def short(data: dict) -> list:
    """A block's rows: one per run, the success of each evaluation (of the lesson ends, the last)
    and, from the fixed start, the precise share (of held-out and, where measured, new targets) and
    the median errors; the page has every row."""
    results, seeds = data["results"], len(data["seeds"])
    present = {kind for kinds in results.values() for kind in kinds}
    after = sorted(k for k in present if k.startswith(AFTER))[-1:]
    kinds = [k for k in SHORT_KINDS if k in present] + after
    titles = [SHORT_KINDS.get(k, f"after {k[len(AFTER):]}") for k in kinds]
    new = "new" in present
    lines = ["| run | " + " | ".join(titles) + " | within 1 cm and 2 deg |"
             + " new, within 1 cm and 2 deg |" * new + " median error |",
             "|---|" + "---|" * (len(kinds) + 2 + new)]
    for label, rows in results.items():
        partial = partial_seeds(rows.get("heldout", next(iter(rows.values()))), seeds)
        cells = [cell(rows[k]["success_rate"], 100, "%") if k in rows else "-" for k in kinds]
        fixed = rows.get("heldout")
        cells.append(cell(fixed["precise_success_rate"], 100, "%") if fixed else "-")
        if new:
            cells.append(cell(rows["new"]["precise_success_rate"], 100, "%") if "new" in rows else "-")
        cells.append(f"{fixed['position_error_median']['mean'] * 100:.2f} cm, "
                     f"{fixed['attitude_error_median']['mean']:.2f} deg" if fixed else "-")
        lines.append(f"| {RUNS.get(label, label)}{partial} | " + " | ".join(cells) + " |")
    return lines
