"""A sweep's runs: seeds x layouts x settings, each a robostrich-train command line with a run
directory of its own (SWEEP/runs/GROUP/seed_K), so that a run is finished exactly when its
summary.json exists and resumable exactly when robostrich-train can resume it.

The grid file is TOML (tomllib, no extra dependency):

    seeds = [0, 1, 2]
    layouts = ["ventral_slips", "antagonist_pairs"]
    [train]                 # robostrich-train flags of every run, without the leading --
    steps = 60000
    no-figures = true
    [settings.her]          # one group per layout and setting
    her-ratio = 0.5
    [settings.plain]

A value true gives the bare flag, false its --no- form, a list the comma-joined items, a table
JSON (for --task-kwargs).
"""
import dataclasses
import json
import os
import re
from typing import Optional

from agents import checkpoint
from robostrich_suite import parsing

GRID_KEYS = ("seeds", "layouts", "train", "settings")
PER_RUN_FLAGS = ("--seed", "--out", "--resume", "--workers")  # the sweep sets these for each run
NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.-]*$")
CHECKPOINTED = ("curriculum", "baseline")  # the run labels of robostrich-train that write a checkpoint


@dataclasses.dataclass(frozen=True)
class Group:
    """Runs that differ only by seed: one layout (or the domain's default) and one setting."""
    name: str
    layout: Optional[str]
    setting: Optional[str]
    arguments: tuple  # robostrich-train flags of every run of the group


@dataclasses.dataclass(frozen=True)
class Run:
    """One robostrich-train command of the sweep, with its own run directory."""
    group: str
    seed: int
    run_dir: str
    arguments: tuple

    @property
    def summary_path(self) -> str:
        return os.path.join(self.run_dir, "summary.json")

    def finished(self) -> bool:
        return os.path.exists(self.summary_path)

    def has_checkpoint(self) -> bool:
        return any(os.path.exists(os.path.join(self.run_dir, label, checkpoint.FILE_NAME)) for label in CHECKPOINTED)

    def argv(self) -> list:
        """robostrich-train's arguments: one worker (the sweep gives each run one core), no bar of
        its own, and --resume where an earlier attempt left a checkpoint."""
        argv = [*self.arguments, "--seed", str(self.seed), "--out", self.run_dir, "--workers", "1", "--quiet"]
        return argv + ["--resume"] if self.has_checkpoint() else argv


def read_grid_file(path: str) -> dict:
    """The grid file's tables, every key known (a typo is an error, not an ignored line); a file
    that is not TOML (torn, not UTF-8, nested too deeply) is a ValueError naming it."""
    grid = parsing.read_toml(path)
    unknown = sorted(set(grid) - set(GRID_KEYS))
    if unknown:
        raise ValueError(f"{path}: unknown key {', '.join(unknown)} (known: {', '.join(GRID_KEYS)})")
    for key in ("train", "settings"):
        if not isinstance(grid.get(key, {}), dict):
            raise ValueError(f"{path}: {key} must be a table ([{key}])")
    for name, table in grid.get("settings", {}).items():
        if not isinstance(table, dict):
            raise ValueError(f"{path}: settings.{name} must be a table ([settings.{name}])")
    return grid


def read_recorded_groups(path: str) -> dict:
    """OUT/grid.json, the flags each group of a sweep started with ({} before the first run); a
    torn or foreign file is a ValueError naming it."""
    if not os.path.exists(path):
        return {}
    recorded = parsing.read_json(path)
    if not (isinstance(recorded, dict) and all(isinstance(flags, list) and all(isinstance(f, str) for f in flags)
                                               for flags in recorded.values())):
        raise ValueError(f"{path}: not the sweep's record of its groups ({{group: [flags, ...]}}); "
                         "choose another --out")
    return recorded


def flags_of(table: dict, where: str) -> list:
    """robostrich-train arguments of a TOML table: {"steps": 6000, "no-figures": true} ->
    ["--steps", "6000", "--no-figures"]."""
    argv = []
    for key, value in table.items():
        flag = "--" + key.removeprefix("--").replace("_", "-")
        if isinstance(value, bool):
            argv.append(flag if value else "--no-" + flag[2:])
        elif isinstance(value, dict):
            argv += [flag, json.dumps(value)]
        elif isinstance(value, list):
            argv += [flag, ",".join(map(str, value))]
        elif isinstance(value, (int, float, str)):
            argv += [flag, str(value)]
        else:
            raise ValueError(f"{where}.{key}: a {type(value).__name__} is no robostrich-train value")
    return argv


def check_names(names, what: str) -> list:
    """Names that become directory names: distinct, and letters, digits, '_', '.', '-' only."""
    names = list(names)
    for name in names:
        if not isinstance(name, str) or not NAME.match(name):
            raise ValueError(f"{what} {name!r}: use letters, digits, '_', '.' and '-' (it names a directory)")
    if len(set(names)) != len(names):
        raise ValueError(f"{what}s repeat a name: {', '.join(names)}")
    return names


def check_seeds(seeds, maximum: int) -> list:
    if not isinstance(seeds, list) or not seeds or not all(type(s) is int and 0 <= s <= maximum for s in seeds):
        raise ValueError(f"seeds must be a list of whole numbers from 0 to {maximum}, got {seeds!r}")
    if len(set(seeds)) != len(seeds):
        raise ValueError(f"seeds repeat: {seeds!r}")
    return seeds


def per_run_flag(argv) -> Optional[str]:
    """The first flag of ``argv`` that the sweep sets for each run itself, if any."""
    for token in argv:
        if token.split("=", 1)[0] in PER_RUN_FLAGS:
            return token.split("=", 1)[0]
    return None


def _group_name(layout, setting) -> str:
    return "+".join(part for part in (layout, setting) if part) or "default"


def build_grid(seeds, layouts, settings: dict, common, out: str):
    """(groups, runs): every layout (None: the domain's own) with every named setting (a dict of
    name -> robostrich-train arguments; empty: one group with only ``common``), each over every seed.
    ``common`` arguments come after a setting's, so the command line has the last word."""
    layouts = check_names(layouts, "layout") if layouts else [None]
    names = check_names(settings, "setting") if settings else [None]
    groups, runs = [], []
    for layout in layouts:
        for setting in names:
            setting_argv = list(settings.get(setting, [])) if setting else []
            flag = per_run_flag(setting_argv + list(common))
            if flag:
                raise ValueError(f"{flag} is set for each run by robostrich-sweep (use --seeds / --out)")
            if layout and any(a.split("=", 1)[0] == "--layout" for a in setting_argv + list(common)):
                raise ValueError("--layout is given by the sweep's layouts; leave it out of the settings")
            arguments = tuple((["--layout", layout] if layout else []) + setting_argv + list(common))
            group = Group(_group_name(layout, setting), layout, setting, arguments)
            groups.append(group)
            runs += [Run(group.name, seed, os.path.join(out, "runs", group.name, f"seed_{seed}"), arguments)
                     for seed in seeds]
    return groups, runs
