"""The Optuna study behind ``robostrich-design``: opening or resuming it, its trials, the front.

A study is fixed to its :class:`Settings` (pose budget, searching the stiffness, the slot's range,
scoring the way in, the tendons' counts and strides; its user attributes): trials scored otherwise do not compare, so resuming
with others is refused.
Each trial stores its measures as the user attribute ``result`` and the constraint
(rolling/lever ratio minus ``RATIO_LIMIT``, feasible at <= 0) as the user attribute
``constraint`` and as Optuna's own constraint, which the sampler reads.
"""
from __future__ import annotations

import dataclasses
import math
import pathlib

from robostrich_suite import cli as cli_lib
from robostrich_suite.model import layouts as layouts_lib
from robostrich_suite.studies import design_objectives, design_space
from robostrich_suite.studies import design_confirm

RATIO_LIMIT = 0.6  # rolling / lever attitude ratio a routing must not pass (design.py's module doc)
OBJECTIVES = ("coverage", "gap_column_m")  # both maximised
PASSAGE_OBJECTIVES = ("coverage", "gap_passage_m")  # with --score-passage
HEARTBEAT_S, GRACE_S = 30, 120  # a trial silent this long was on a machine that died: failed
FRONT_LAYOUTS = 10  # the front's routings written as layout files, best gap column first


def objectives(score_passage: bool) -> tuple:
    return PASSAGE_OBJECTIVES if score_passage else OBJECTIVES

MAX_RATIO = 1e3  # a routing whose lever hardly turns the head: the ratio is "huge", kept finite


@dataclasses.dataclass(frozen=True)
class Settings:
    """What a study's trials are scored with, fixed when it starts (robostrich-design's flags)."""
    pose_budget: int = 36
    search_stiffness: bool = False
    slot_x: tuple | None = None  # (min, max) m of the slot's centre; None: anywhere
    score_passage: bool = False
    space: design_space.Space = design_space.PAPER

    def attrs(self) -> dict:
        return {"pose_budget": self.pose_budget, "search_stiffness": self.search_stiffness,
                "slot_x": None if self.slot_x is None else list(self.slot_x), "score_passage": self.score_passage,
                "dorsal_tendons": self.space.dorsal, "ventral_tendons": self.space.ventral,
                "max_hole_stride": self.space.max_stride}

    @classmethod
    def of(cls, study) -> "Settings":
        """The settings ``study`` was started with (one started before a flag existed: its default)."""
        attrs = study.user_attrs
        slot_x = attrs.get("slot_x")
        space = design_space.Space(attrs.get("dorsal_tendons", design_space.DORSAL_TENDONS),
                                   attrs.get("ventral_tendons", design_space.VENTRAL_TENDONS),
                                   attrs.get("max_hole_stride", 1))
        return cls(attrs.get("pose_budget", cls.pose_budget), bool(attrs.get("search_stiffness")),
                   None if slot_x is None else tuple(slot_x), bool(attrs.get("score_passage")), space)

    def flags(self) -> str:
        return (f"--pose-budget {self.pose_budget}" + (" --search-stiffness" if self.search_stiffness else "")
                + (f" --slot-x {self.slot_x[0]:g},{self.slot_x[1]:g}" if self.slot_x is not None else "")
                + (" --score-passage" if self.score_passage else "")
                + (f" --dorsal-tendons {self.space.dorsal}" if self.space.dorsal != design_space.DORSAL_TENDONS else "")
                + (f" --ventral-tendons {self.space.ventral}" if self.space.ventral != design_space.VENTRAL_TENDONS else "")
                + (f" --max-hole-stride {self.space.max_stride}" if self.space.max_stride != 1 else ""))


def _optuna():
    """Optuna, saying nothing below an error: a trial that fails (Ctrl-C, SIGTERM or a defect)
    raises to the command (``catch=()``), which ends in its one line; Optuna's warning would repeat
    it with a traceback first."""
    import optuna
    optuna.logging.set_verbosity(optuna.logging.ERROR)
    return optuna


def sampler(seed: int):
    """Multi-objective TPE; it reads each trial's constraint (``Trial.set_constraint``) itself."""
    optuna = _optuna()
    return optuna.samplers.TPESampler(seed=seed, constant_liar=True)


def open_study(url: str, name: str, settings: Settings, seed: int):
    """The study ``name`` in ``url``, made if new; ValueError (one line) for a bad URL or a study
    of other :class:`Settings`.  The sampler's seed is offset by the trials it holds, so a resumed study
    does not draw its first routings again."""
    optuna = _optuna()
    try:
        storage = optuna.storages.RDBStorage(url, heartbeat_interval=HEARTBEAT_S,
                                             grace_period=GRACE_S)
    except Exception as error:  # SQLAlchemy's URL, driver and connection errors have no common base
        if isinstance(error, (KeyboardInterrupt, SystemExit)):
            raise
        raise ValueError(f"--storage {redacted(url)}: {type(error).__name__}: {error}") from None
    study = optuna.create_study(storage=storage, study_name=name, load_if_exists=True,
                                directions=["maximize"] * len(OBJECTIVES))
    if list(study.directions) != [optuna.study.StudyDirection.MAXIMIZE] * len(OBJECTIVES):
        raise ValueError(f"study {name!r} in {redacted(url)} is not a robostrich-design study")
    if not study.user_attrs:
        for key, value in settings.attrs().items():
            study.set_user_attr(key, value)
    elif Settings.of(study) != settings:
        raise ValueError(f"study {name!r} was started with {Settings.of(study).flags()}, not {settings.flags()}: "
                         "resume it with the same, or give another --study-name")
    study.sampler = sampler(seed + len(study.trials))
    return study


def redacted(url: str) -> str:
    """``url`` without its password (it is printed and written into design.json)."""
    try:
        from sqlalchemy.engine import make_url
        return make_url(url).render_as_string(hide_password=True)
    except Exception:  # not a URL at all: nothing to hide that make_url could find
        return url


def start_layout(item: str, space: design_space.Space = design_space.PAPER):
    """A built-in layout's name or a layout file, as search parameters (ValueError if outside ``space``)."""
    if item.lower().endswith((".json", ".toml")):
        name, layout = layouts_lib.read_file(item, design_space.SPEC)
    else:
        name, layout = item, layouts_lib.build(item)
    try:
        return design_space.parameters(layout, space=space)
    except ValueError as error:
        raise ValueError(f"--start-from {name}: {error}") from None


def enqueue_once(study, starts: list, stiffness: bool) -> None:
    """Queue the ``--start-from`` routings as a new study's first trials."""
    if not starts or study.user_attrs.get("started_from"):
        return
    for params in starts:
        if stiffness:
            params = {**params, "stiffness": design_space.SPEC.joint_stiffness}
        study.enqueue_trial(params)
    study.set_user_attr("started_from", len(starts))


def complete_trials(study) -> list:
    optuna = _optuna()
    return study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))


def objective(settings: Settings):
    budget = design_objectives.Budget(poses=settings.pose_budget)

    def score(trial):
        params = design_space.suggest(trial, settings.search_stiffness, settings.space)
        result = design_objectives.evaluate(design_space.spec(params), design_space.layout(params), budget,
                                            cli_lib.interrupted, settings.slot_x, settings.score_passage)
        ratio = result["rolling_lever_ratio"]
        ratio = MAX_RATIO if ratio is None or not math.isfinite(ratio) else min(ratio, MAX_RATIO)
        result["rolling_lever_ratio"] = ratio
        trial.set_user_attr("result", result)
        trial.set_user_attr("constraint", ratio - RATIO_LIMIT)
        trial.set_constraint("rolling_lever_ratio", ratio - RATIO_LIMIT)
        return tuple(result[name] for name in objectives(settings.score_passage))
    return score


def run_trials(study, trials: int, settings: Settings, show_progress: bool = True) -> None:
    """Trials until the study holds ``trials`` complete ones; Ctrl-C (polled between poses) fails the
    running trial and stops (the caller raises it)."""
    from tqdm import tqdm
    done = len(complete_trials(study))
    if done >= trials:
        return
    score = objective(settings)
    what = "way in" if settings.score_passage else "column"
    with tqdm(total=trials, initial=done, desc="routings", unit="trial", disable=not show_progress,
              mininterval=1.0) as bar:
        while done < trials and not cli_lib.interrupted():
            try:
                study.optimize(score, n_trials=1, catch=())
            except KeyboardInterrupt:  # Optuna marked the trial failed and committed that
                return
            now = len(complete_trials(study))
            bar.update(now - done)
            done = now
            front = pareto_front(study)
            if front:
                best = max(front, key=lambda t: (t.values[1], t.values[0]))
                bar.set_postfix_str(f"front {len(front)}, best {what} {100 * best.values[1]:.1f} cm")


def feasible(trial) -> bool:
    return trial.user_attrs.get("constraint", MAX_RATIO) <= 0


def pareto_front(study) -> list:
    """The feasible complete trials no other feasible one beats on both objectives, best gap column
    first (ties: coverage, then the earlier trial)."""
    trials = [t for t in complete_trials(study) if feasible(t)]
    front = [t for t in trials
             if not any(all(o >= s for o, s in zip(other.values, t.values)) and other.values != t.values
                        for other in trials)]
    unique = {}
    for t in front:  # equal scores: the first trial stands for them
        unique.setdefault(tuple(t.values), t)
    return sorted(unique.values(), key=lambda t: (-t.values[1], -t.values[0], t.number))


CONFIRMED = "confirmed_trial_"  # study user attribute of a confirmed trial's full measures, by its number


def confirmed(study) -> list:
    """The full measures of every confirmed trial, in trial order."""
    rows = [value for key, value in study.user_attrs.items() if key.startswith(CONFIRMED)]
    return sorted(rows, key=lambda row: row["trial"])


def confirm(study, count: int, out: pathlib.Path, show_progress: bool = True) -> list:
    """The full measures of the front's best ``count`` routings (module doc of design), each kept in
    the study once measured (a later run reports it without measuring it again)."""
    if not count or cli_lib.interrupted():
        return confirmed(study)
    done = {row["trial"]: row for row in confirmed(study)}
    todo = [t for t in pareto_front(study)[:count] if t.number not in done]
    slot_x = Settings.of(study).slot_x
    for row in design_confirm.confirm(todo, out, show_progress, slot_x):
        study.set_user_attr(f"{CONFIRMED}{row['trial']}", row)
    for number, row in done.items():  # confirmed before the passage was measured: only that is added
        if "passage" not in row:
            study.set_user_attr(f"{CONFIRMED}{number}",
                                {**row, **design_confirm.gap_measures(study.trials[number], slot_x)})
    return confirmed(study)
