"""Tables of a "design" results record: robostrich-design's search of tendon routings (its
design.json): the Pareto front of coverage and gap column, with the full measures of those confirmed."""
import json

ROW_NOISE = ("layout_file", "target_file")  # where one run wrote its files: not a result


def read(data: dict, path: str) -> tuple:
    if "front" not in data or "trials" not in data or "need" not in data:
        raise ValueError(f"{path} is not robostrich-design's design.json (no 'front'/'trials'/'need')")
    data = json.loads(json.dumps(data))
    for row in data["front"] + data.get("confirmed", []):
        for key in ROW_NOISE:
            row.pop(key, None)
    return data, data.get("command")


def scoring(data: dict) -> str:
    """Which second objective the study used, and where its slot was held (records before the flags
    existed: the column, the slot anywhere, and nothing said)."""
    if "gap_objective" not in data:
        return ""
    slot = data.get("slot_x")
    where = "anywhere" if slot is None else f"{100 * slot[0]:.0f} to {100 * slot[1]:.0f} cm ahead of the base joint"
    if data["gap_objective"] != "passage":
        return f"; scored by coverage and the gap column, the slot {where}"
    best = ("no routing feasible" if not data["trials"]["feasible"] else
            f"best feasible {100 * data['best_feasible_passage_m']:+.1f} cm from the shelf's top")
    what = f"the way in from under the shelf (how far up through the slot the head gets; {best})"
    return f"; scored by coverage and {what}, the slot {where}"


def family(data: dict) -> str:
    """The tendons of the study's routings when beyond the paper's family (1 dorsal, 8 ventral, every
    link holed); nothing for the paper's or for records before the flags existed."""
    tendons = data.get("tendons") or {"dorsal": 1, "ventral": 8, "max_hole_stride": 1}
    if tendons == {"dorsal": 1, "ventral": 8, "max_hole_stride": 1}:
        return ""
    skip = (f", holes up to {tendons['max_hole_stride']} links apart" if tendons["max_hole_stride"] > 1
            else ", every link holed")
    return f"; beyond the paper's family: {tendons['dorsal']} dorsal and {tendons['ventral']} ventral tendons{skip}"


def caption(data: dict) -> str:
    trials, need = data["trials"], data["need"]
    rate = (f", {trials['trials_per_core_hour']:g} trials per hour of one core ({trials['trials_per_hour']:g} "
            "per hour on the clock, the core shared)" if trials.get("trials_per_core_hour") else "")
    return (f"{trials['complete']} routings ({trials['feasible']} with rolling/lever <= {data['ratio_limit']:g}) at "
            f"{data['pose_budget']} sought poses each{rate}; best gap column "
            f"{100 * data['best_feasible_gap_column_m']:.1f} cm ({100 * data['best_gap_column_m']:.1f} cm of any routing), "
            f"the narrow gap needs {100 * need['column_height_m']:.0f} cm above its shelf{scoring(data)}{family(data)}")


def _percent(value) -> str:
    return "n/a" if value is None else f"{value:.0%}"


def _column(row: dict) -> str:
    gap = row.get("gap") or {}
    where = (f" (slot at x {100 * gap['slot_x_m']:.1f} cm, shelf {100 * gap['shelf_z_m']:.1f} cm up)"
             if gap.get("slot_x_m") is not None and row["gap_column_m"] else "")
    return f"{100 * row['gap_column_m']:.1f} cm{where}"


def _passage(row: dict) -> str:
    passage = row.get("passage")
    if not passage:
        return "not measured"
    if not passage["ramps"]:
        return f"no pose under the shelf ({passage['samples']} drawn)"
    highest = passage["highest_in_slot_m"]
    where = ("the head never over the slot" if highest is None else
             f"the head at most {100 * highest:+.1f} cm from the shelf's top over the slot before a touch")
    return f"{passage['clear']} of {passage['ramps']} ramps clear; {where}"


def _way_in(row: dict) -> str:
    passage = row.get("passage") or {}
    return f"{100 * row['gap_passage_m']:+.1f} cm ({_passage(row)}; into: {passage.get('target') or 'nothing'})"


def short(data: dict) -> list:
    """The front (cheap scores, with the full measures where a routing has them), then every routing
    confirmed, on the front now or not."""
    confirmed = {row["trial"]: row for row in data.get("confirmed", [])}
    passage = data.get("gap_objective") == "passage"
    lines = ["| trial | coverage (sampled cells) | gap column | " + ("way in (cheap) | " if passage else "")
             + "rolling / lever | confirmed coverage | confirmed gap column | confirmed rolling / lever |",
             "|---|---|---|---|---|---|---|" + ("---|" if passage else "")]
    for row in data["front"]:
        check = confirmed.get(row["trial"])
        later = ([_percent(check["coverage"]), _column(check), f"{check['rolling_lever_ratio']:.2f}"] if check
                 else ["-", "-", "-"])
        lines.append(f"| {row['trial']} | {_percent(row['coverage'])} | {_column(row)} | "
                     + (f"{_way_in(row)} | " if passage else "")
                     + f"{row['rolling_lever_ratio']:.2f} | " + " | ".join(later) + " |")
    if confirmed:
        lines += ["", "Confirmed (robostrich-layouts' measures, every blue cell; the gap column at the full budget):", "",
                  "| trial | coverage | distinct level targets | gap column | rolling / lever | "
                  "from under the shelf into the column |", "|---|---|---|---|---|---|"]
        lines += [f"| {row['trial']} | {_percent(row['coverage'])} ({row['covered_cells']} of {row['blue_cells']} cells) | "
                  f"{row['distinct_targets']} | {_column(row)} | {row['rolling_lever_ratio']:.2f} | {_passage(row)} |"
                  for row in confirmed.values()]
    return lines


def full(data: dict) -> list:
    return short(data)
