"""Tables of a "speed" results record: a speed benchmark's rates and its ratios against a baseline
measured in the same run (tools/benchmark_env.py, benchmark_a1.py, benchmark_learner.py --json)."""


def read(data: dict, path: str) -> tuple:
    if not data.get("ratios"):
        raise ValueError(f"{path} is not a speed benchmark's --json output (no 'ratios')")
    return data, data.get("command")


def caption(data: dict) -> str:
    return data.get("description", "").rstrip(".")


def _ratio(row: dict) -> str:
    spread = f" [{row['low']:.3f}, {row['high']:.3f}]" if row.get("low") is not None else ""
    return f"**{row['value']:.3f}**{spread}"


def full(data: dict) -> list:
    """Rates first (what was measured), then the ratios the benchmark exists for."""
    lines = ["| measured | value |", "|---|---|"]
    lines += [f"| {row['what']} | {row['value']:,.0f} {row['unit']} |" for row in data.get("rates", [])]
    lines += [f"| ratio {row['what']} | {_ratio(row)} |" for row in data["ratios"]]
    return lines


def short(data: dict) -> list:
    return ["| ratio | value |", "|---|---|"] + [f"| {row['what']} | {_ratio(row)} |" for row in data["ratios"]]
