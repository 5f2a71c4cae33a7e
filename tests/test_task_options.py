"""Every option of every task, given nonsense, fails when the task is built with a TypeError or
ValueError naming the option: never an AttributeError in the first episode, numpy's words without
the option's name, or a number too large to mean anything (a 1e300 s episode)."""
import dataclasses
import inspect
import math

import numpy as np
import pytest

import robostrich_suite
from robostrich_suite.tasks import options, perturbations, randomization, reach, rewards

NESTED = {  # options that are a dict of a class's fields (JSON's form) or an instance of it
    "weights": [f.name for f in dataclasses.fields(rewards.RewardWeights)],
    "randomization": [f.name for f in dataclasses.fields(randomization.DomainRandomization)],
    "perturbation": [f.name for f in dataclasses.fields(perturbations.Perturbation)],
    "environment_kwargs": list(options.ENVIRONMENT_OPTIONS),
}
NUMBERS_WITHOUT_DEFAULT = ("time_limit", "random")  # default None, a number when given
NONSENSE = ("abc", [[[]]], {"x": 1})  # a string, a nested list, an object where none of them fits
TOO_LARGE = (1e300, math.nan, -1e300)


def _task_options(domain: str, task: str) -> dict:
    """{option: its default} of a task: its factory's parameters, those of every class of its task
    (the reaching tasks take ReachConfig's fields as keywords)."""
    factory = robostrich_suite._DOMAINS[domain].SUITE[task]
    found = {}
    env = robostrich_suite.load(domain, task, task_kwargs=dict(random=0))
    for cls in type(env.task).__mro__:
        if cls.__module__.startswith("robostrich_suite") and "__init__" in vars(cls):
            found.update(_parameters(cls.__init__))
    found.update({f.name: f.default for f in dataclasses.fields(reach.ReachConfig)})
    found.update(_parameters(factory))
    found.pop("self", None)
    found.pop("config", None)  # the ReachConfig itself, whose fields are the options above
    return found


def _parameters(function) -> dict:
    return {name: p.default for name, p in inspect.signature(function).parameters.items()
            if p.kind not in (p.VAR_KEYWORD, p.VAR_POSITIONAL)}


def _is_numeric(name, default) -> bool:
    if name in NUMBERS_WITHOUT_DEFAULT:
        return True
    if isinstance(default, tuple):
        return bool(default) and all(options._is_real(v) for v in default)
    return options._is_real(default)


def _refused(domain, task, kwargs, name):
    with pytest.raises((TypeError, ValueError)) as caught:
        robostrich_suite.load(domain, task, task_kwargs=dict(random=0, **kwargs))
    assert name in str(caught.value), (domain, task, kwargs, str(caught.value))


@pytest.mark.parametrize("domain, task", robostrich_suite.ALL_TASKS)
def test_every_option_refuses_nonsense_naming_itself(domain, task):
    found = _task_options(domain, task)
    assert {"time_limit", "random", "weights", "target_pool"} <= set(found)  # the collection works
    for name, default in found.items():
        for value in NONSENSE:
            _refused(domain, task, {name: value}, name)
        if _is_numeric(name, default):
            for value in TOO_LARGE:
                _refused(domain, task, {name: (value,) * len(default) if isinstance(default, tuple) else value}, name)
    for name, fields in NESTED.items():
        for field in fields:
            for value in ("abc", 1e300):
                _refused(domain, task, {name: {field: value}}, field)
        _refused(domain, task, {name: {"nope": 1}}, "nope")


def test_the_reported_options_name_themselves():
    for kwargs, error, words in [
        (dict(randomization="yes"), TypeError, "randomization must be a DomainRandomization"),
        (dict(target_pool="abc"), ValueError, "target_pool must be a non-empty (n, 2) array"),
        (dict(weights="x"), TypeError, "weights must be a RewardWeights"),
        (dict(time_limit=1e300), ValueError, f"time_limit must be positive seconds, at most {options.MAX_SECONDS:g}"),
    ]:
        with pytest.raises(error) as caught:
            robostrich_suite.load("robostrich", "lesson2", task_kwargs=kwargs)
        assert words in str(caught.value)


def test_options_as_json_gives_them_are_accepted():
    """Lists for tuples, dicts for the option classes: what --task-kwargs passes."""
    env = robostrich_suite.load("robostrich", "lesson3", task_kwargs=dict(
        random=0, time_limit=options.MAX_SECONDS, randomization={"mass_scale": [0.8, 1.2]},
        weights={"position_precision": 1.0}, target_axes=[0, 2], environment_kwargs={"flat_observation": False}))
    assert env.task.randomizer.config.mass_scale == (0.8, 1.2)
    assert env.task.weights.position_precision == 1.0
    quadruped = robostrich_suite.load("robostrich_a1", "head_stabilize", task_kwargs=dict(
        random=0, trunk_heights={"times": [0.0, 1.0], "heights": [0.27, 0.22]}, steer=False))
    assert quadruped.task.steer is False
    np.testing.assert_allclose(quadruped.task._trunk_heights(1.0), 0.22)


def test_target_jitter_moves_each_drawn_target_within_its_radius_and_off_it_draws_the_pool_itself():
    pool = np.array([[0.3, 0.2], [0.1, 0.5]])
    drawn = {}
    for jitter in (0.0, 0.02):
        env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=3, target_pool=pool,
                                                                              target_jitter=jitter))
        drawn[jitter] = []
        for _ in range(40):
            env.reset()
            drawn[jitter].append(env.task.target_position.copy())
    off = np.min(np.linalg.norm(np.array(drawn[0.0])[:, None] - pool[None], axis=2), axis=1)
    assert np.all(off == 0.0)
    moved = np.min(np.linalg.norm(np.array(drawn[0.02])[:, None] - pool[None], axis=2), axis=1)
    assert np.all(moved <= 0.02) and np.all(moved > 0) and moved.max() > 0.015  # spread over the disk


def test_target_between_draws_along_the_segments_to_each_poses_nearest_neighbour_only():
    pool = np.array([[0.0, 0.2], [0.1, 0.2], [0.1, 0.32], [0.5, 0.5]])
    nearest = [(0, 1), (1, 0), (2, 1), (3, 2)]  # (pose, its nearest other pose)
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=5, target_pool=pool,
                                                                          target_between=1))
    drawn = []
    for _ in range(60):
        env.reset()
        drawn.append(env.task.target_position.copy())
    drawn = np.array(drawn)

    def off_segment(a, b):
        share = np.clip((drawn - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
        return np.linalg.norm(drawn - (a + share[:, None] * (b - a)), axis=1)
    off = np.min([off_segment(pool[i], pool[j]) for i, j in nearest], axis=0)
    assert np.all(off < 1e-9)
    assert np.min(np.linalg.norm(drawn[:, None] - pool[None], axis=2), axis=1).max() > 0.04  # between, not at
    assert len(np.unique(np.round(drawn, 6), axis=0)) > 40
    with pytest.raises(ValueError, match="target_between must be a whole number of nearest neighbours"):
        robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(target_between=2.5))
