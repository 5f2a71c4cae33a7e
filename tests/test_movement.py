"""Rolling and lever movement tests (paper Sec. 4.3, Figs. 4-5), from real simulations.

Measured with the defaults (dorsal tendon paid out 20 mm and its *length* held,
every ventral tendon ramped to 50 mm or its range, 1 s per tendon):

    rolling: head travel 190 mm, attitude 84.6 -> 109.4 deg, range 25.0 deg
    lever:   head travel 191 mm, attitude 84.6 -> 109.0 deg, range 25.4 deg

The paper's difference (rolling keeps the attitude, lever changes it) does *not*
show in this model: with the dorsal tendon's length held, the settled poses form
nearly a one-parameter family in which the head attitude is a function of the head
position (100 random ventral inputs: poses within 15 mm differ by a median 0.6 deg),
so any ventral sequence that moves the head the same way turns it the same way.
The paper's claim is kept below as a strict xfail: it starts failing loudly (XPASS)
when a change to the arm makes the difference appear, and the thresholds must then
be measured again.  Travelling-wave rolling (each tendon let go as the next one
contracts), both directions, the dorsal input held instead of its length, stiffer
joints, other hole positions and short ventral tendons were also tried without a
robust difference; numbers in the docstring of ``robostrich_suite.movement``.
"""
import shutil
import subprocess
import sys
import pathlib

import numpy as np
import pytest

from robostrich_suite import movement


@pytest.fixture(scope="module")
def runs():
    return {pattern: movement.run(movement.MovementConfig(pattern))
            for pattern in movement.PATTERNS}


def test_both_patterns_start_from_the_same_level_pose(runs):
    rolling, lever = runs["rolling"], runs["lever"]
    start = np.flatnonzero(rolling.moving)[0]
    np.testing.assert_allclose(rolling.head_position[start], lever.head_position[start],
                               atol=1e-9)
    assert abs(rolling.head_attitude[start] - 90) < 10  # measured 84.6 deg


def test_both_patterns_move_the_head_comparably(runs):
    travel = {p: m.head_travel() for p, m in runs.items()}
    assert travel["rolling"] > 0.12 and travel["lever"] > 0.12  # measured 190 and 191 mm
    assert travel["rolling"] == pytest.approx(travel["lever"], rel=0.25)


def test_dorsal_tendon_length_is_held(runs):
    for run in runs.values():
        dorsal = run.tendon_names.index("dorsal")
        error = np.abs(run.contraction[run.moving, dorsal] - run.config.dorsal)
        assert error.max() < 0.004  # m; measured 0.5-2 mm


def test_rolling_contracts_one_after_another_lever_all_at_once(runs):
    ventral = [i for i, n in enumerate(runs["rolling"].tendon_names) if "ventral" in n]

    def onsets(run):
        moving = run.control[:, ventral] > 1e-6
        return np.array([run.time[np.argmax(column)] for column in moving.T[1:]])

    rolling, lever = onsets(runs["rolling"]), onsets(runs["lever"])
    assert np.all(np.diff(rolling) > 0.5)  # caudal to cranial, 1 s apart
    assert np.ptp(lever) < 0.05


def test_attitude_follows_head_position_in_both_patterns(runs):
    """Why the patterns do not differ here: where their head paths meet, so do attitudes."""
    rolling, lever = runs["rolling"], runs["lever"]
    a = rolling.head_position[rolling.moving]
    b = lever.head_position[lever.moving]
    distance = np.linalg.norm(a[:, None] - b[None], axis=2)
    i, j = np.nonzero(distance < 0.005)
    assert len(i) > 50
    difference = np.abs(rolling.head_attitude[rolling.moving][i]
                        - lever.head_attitude[lever.moving][j])
    assert np.median(difference) < 3.0  # deg; measured 0.3


@pytest.mark.xfail(strict=True, reason=(
    "The model as built does not show the paper's rolling/lever difference: attitude range "
    "25.0 deg (rolling) vs 25.4 deg (lever) for 190 mm of head travel each"))
def test_rolling_keeps_attitude_range_much_smaller_than_lever(runs):
    assert runs["rolling"].attitude_range() < 0.5 * runs["lever"].attitude_range()


def _rerun_cli():
    candidate = pathlib.Path(sys.executable).parent / "rerun"
    return str(candidate) if candidate.exists() else shutil.which("rerun")


def test_command_line_writes_figures_and_valid_recordings(tmp_path):
    results = movement.main(["--out", str(tmp_path), "--ramp-time", "0.25", "--no-progress"])
    assert set(results) == set(movement.PATTERNS)
    cli = _rerun_cli()
    assert cli, "the rerun command of rerun-sdk is not installed"
    for pattern in movement.PATTERNS:
        png = tmp_path / f"{pattern}.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
        rrd = tmp_path / f"{pattern}.rrd"
        assert rrd.stat().st_size > 100_000
        check = subprocess.run([cli, "rrd", "verify", str(rrd)], capture_output=True, text=True)
        assert check.returncode == 0, check.stderr
