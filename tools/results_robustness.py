"""Tables of a "robustness" results record: held-out success as the robot differs from its model
(robostrich-robustness's robustness.json; what scale s means per family:
robostrich_suite/tasks/perturbations.py)."""

from agents.robostrich.robustness.figure import KINDS


def read(data: dict, path: str) -> tuple:
    if not data.get("results") or not data.get("scales"):
        raise ValueError(f"{path} is not robostrich-robustness's robustness.json (no 'results')")
    return data, data.get("command")


def caption(data: dict) -> str:
    first = next(iter(data["results"][data["labels"][0]].values()))[0]
    return (f"held-out success (%) of {data['policy']} on {data['domain']}, {data['num_targets']} held-out targets, "
            f"as each family of differences (robostrich_suite/tasks/perturbations.py) grows to scale s, then all "
            f"at once; " + " / ".join(words for kind, words in KINDS.items() if kind in first))


def _cell(row: dict) -> str:
    return " / ".join(f"{100 * row[kind]['success_rate']:.0f}" for kind in KINDS if kind in row)


def _table(data: dict, label: str) -> list:
    scales = data["scales"]
    lines = [f"| {label}: family | " + " | ".join(f"s = {s:g}" for s in scales) + " |",
             "|---|" + "---|" * len(scales)]
    for family, rows in data["results"][label].items():
        by_scale = {r["scale"]: r for r in rows}
        lines.append(f"| {family} | " + " | ".join(_cell(by_scale[s]) if s in by_scale else "-" for s in scales)
                     + " |")
    return lines


def _falls_below(data: dict) -> list:
    lines = ["| family | success below 90 % from | below 80 % from |", "|---|---|---|"]
    for family, levels in data["falls_below"].items():
        cells = ["-" if levels.get(k) is None else f"s = {levels[k]:g}" for k in ("0.9", "0.8")]
        lines.append(f"| {family} | " + " | ".join(cells) + " |")
    return lines + ["", "(fixed start; - : not below at any scale measured)"]


def full(data: dict) -> list:
    """One table per evaluated policy (the policy, a compared one, the lookup), then where it falls."""
    lines = []
    for label in data["labels"]:
        lines += _table(data, label) + [""]
    return lines + _falls_below(data)


def short(data: dict) -> list:
    return _table(data, data["labels"][0]) + [""] + _falls_below(data)
