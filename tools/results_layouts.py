"""Tables of a "layouts" results record: robostrich-layouts' comparison of tendon routings
(its layouts.json), rendered with the command's own table so both read alike."""
import json
from robostrich_suite.studies import layout_compare

ROW_NOISE = ("target_file",)  # where one run wrote its files: not a result


def read(data: dict, path: str) -> tuple:
    if not data.get("rows") or "blue_region" not in data:
        raise ValueError(f"{path} is not robostrich-layouts' layouts.json (no 'rows'/'blue_region')")
    data = json.loads(json.dumps(data))
    for row in data["rows"]:
        for key in ROW_NOISE:
            row.pop(key, None)
    return data, data.get("command")


def caption(data: dict) -> str:
    text = layout_compare.describe_samples(data["blue_region"]).rstrip(".")
    return text[0].lower() + text[1:]  # it follows the command and date


def full(data: dict) -> list:
    return layout_compare.markdown_table(data["rows"]).rstrip("\n").split("\n")


short = full
