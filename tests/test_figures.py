"""What a reader of the figures sees, read from the matplotlib Figures the tools draw
(no pixels): titles and panel letters, labels of every reference line and band, a
colourbar where colour means time, nothing hidden under a legend, and a success
rate on its whole [0, 1] range.  The data come from short real simulations."""
import pathlib
import subprocess
import sys

import matplotlib.pyplot as plt
import numpy as np
import pytest

from agents.robostrich import figures
from agents.robostrich.domains import Domain, as_domain
from agents.robostrich.evaluate import episodes
from agents.replay import ObservationFlattener
from robostrich_suite.studies import movement, movement_figure, walk, walk_figure
from robostrich_suite.tasks import quadruped_tasks

ARM = Domain("robostrich")  # the frame arm with its own routing


class ZeroTendons:
    """The passive arm: never contracts a tendon (so it never succeeds)."""

    def select_action(self, observation):
        return np.zeros(9)


def _draw(fig):
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def _legend_labels(ax):
    legend = ax.get_legend()
    return [] if legend is None else [t.get_text() for t in legend.get_texts()]


def _line(ax, label):
    return next(line for line in ax.get_lines() if line.get_label() == label)


def _panel_titles(fig, count):
    axes = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    return [ax.get_title() for ax in axes[:count]]


@pytest.fixture(scope="module")
def rolling():
    """The default rolling test, quick ramps: 50 mm asked, each slip clipped to its range."""
    run = movement.run(movement.MovementConfig("rolling", ramp_time=0.25))
    fig = movement_figure.movement_figure(run)
    yield run, fig
    plt.close(fig)


def test_rolling_and_lever_share_one_figure_with_their_ratio_against_the_goal(rolling):
    """The ratio is the point: both patterns on one attitude axis, the ratio and its goal in the title."""
    run, _ = rolling
    lever = movement.run(movement.MovementConfig("lever", ramp_time=0.25))
    fig = movement_figure.comparison_figure({"rolling": run, "lever": lever})
    try:
        ratio = run.attitude_range() / lever.attitude_range()
        assert f"rolling / lever at equal head travel: {ratio:.2f} (goal" in fig._suptitle.get_text()
        labels = _legend_labels(fig.axes[0])
        assert labels[0].startswith(f"rolling: range {run.attitude_range():.1f} deg") and labels[1].startswith("lever")
    finally:
        plt.close(fig)


def test_movement_figure_has_panel_letters_and_a_time_colourbar(rolling):
    _, fig = rolling
    titles = _panel_titles(fig, 3)
    assert [t[:3] for t in titles] == ["(A)", "(B)", "(C)"]
    colourbars = [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]
    assert len(colourbars) == 1 and colourbars[0].get_ylabel() == "time (s)"


def test_movement_figure_states_the_ventral_amplitudes_it_plots(rolling):
    run, fig = rolling
    inputs = fig.axes[0]
    peaks = np.array([_line(inputs, name).get_ydata().max()
                      for name in run.tendon_names if name != "dorsal"])
    # frames every 8 ms sample the quick triangles' tips to within 2 %
    np.testing.assert_allclose(peaks, 1000 * run.ventral_amplitudes, rtol=0.02)
    assert peaks.max() < 40  # the 50 mm asked is clipped: the text must not claim it
    said = f"{1000 * run.ventral_amplitudes.min():.0f}-{1000 * run.ventral_amplitudes.max():.0f} mm"
    assert said in inputs.get_title() and said in run.amplitude_text()
    assert "50.0 mm asked" in run.amplitude_text()


def test_movement_figure_base_joint_marker_is_on_top_and_not_under_the_legend(rolling):
    run, fig = rolling
    arm_axes = fig.axes[2]
    renderer = _draw(fig)
    marker = _line(arm_axes, "C18-frame joint (base)")
    assert marker.get_zorder() > max(line.get_zorder() for line in arm_axes.get_lines()
                                     if line is not marker)
    point = arm_axes.transData.transform(run.joint_points[0, 0])
    assert arm_axes.get_window_extent(renderer).contains(*point)
    assert not arm_axes.get_legend().get_window_extent(renderer).contains(*point)


@pytest.fixture(scope="module")
def walk_series():
    return walk.record_walk("head_stabilize", seconds=0.4)


def test_walk_draws_the_target_p_d_and_the_trunk_height_on_its_own_scale(walk_series):
    fig = walk_figure.walk_figure(walk_series, "head_stabilize")
    try:
        titles = _panel_titles(fig, 5)
        assert [t[:3] for t in titles] == ["(A)", "(B)", "(C)", "(D)", "(E)"]
        target = _line(fig.axes[3], "target $P_d$")
        np.testing.assert_allclose(target.get_ydata(), quadruped_tasks.HEAD_STABILIZE_DISTANCE)
        np.testing.assert_allclose(_line(fig.axes[0], "target head height").get_ydata(),
                                   quadruped_tasks.HEAD_STABILIZE_HEIGHT)
        trunk_axes = [ax for ax in fig.axes if "trunk height" in _legend_labels(ax)]
        assert len(trunk_axes) == 1 and "head height" not in _legend_labels(trunk_axes[0])
    finally:
        plt.close(fig)


def test_walk_legends_sit_beside_the_data_not_on_it(walk_series):
    fig = walk_figure.walk_figure(walk_series)
    try:
        renderer = _draw(fig)
        for ax in fig.axes:
            legend = ax.get_legend().get_window_extent(renderer)
            assert legend.x0 >= ax.get_window_extent(renderer).x1
    finally:
        plt.close(fig)


@pytest.fixture(scope="module")
def passive_arm_reports():
    """Learning-curve records and a track report of the passive arm, from real episodes."""
    flattener = ObservationFlattener(as_domain("robostrich").make_environment("lesson2", 0).observation_spec())
    actor = ZeroTendons()
    records, steps = [], 0
    for task in ("lesson1", "lesson2"):
        report = episodes.evaluate_heldout(actor, flattener, ARM, task, ARM.heldout_targets(2))
        for episode in report["episodes"]:
            steps += episode["steps"]
            records.append(dict(env_steps=steps, task=task, **{k: episode[k] for k in ("return", "success")}))
    evals = [dict(env_steps=steps, summary=report["summary"])]
    track = episodes.evaluate_track(actor, flattener)
    return {"records": records, "evals": evals, "boundary": records[1]["env_steps"], "track": track}


def test_learning_curves_have_titles_labelled_lines_and_a_whole_success_axis(passive_arm_reports):
    data = passive_arm_reports
    assert not any(r["success"] for r in data["records"])  # all zero: the axis must still be 0..1
    fig = figures.learning_curves_figure({"curriculum": data["records"]}, {"curriculum": data["evals"]},
                                         lesson_boundaries=[data["boundary"]])
    try:
        assert fig._suptitle is not None and fig._suptitle.get_text()
        assert [t[:3] for t in _panel_titles(fig, 3)] == ["(a)", "(b)", "(c)"]
        low, high = fig.axes[1].get_ylim()
        assert low <= 0 < 1 <= high and high - low < 1.2
        assert "position tolerance (50 mm)" in _legend_labels(fig.axes[2])
        # (b) compares held-out with held-out: the evaluations' success, training episodes only behind it
        assert {"curriculum SAC, held-out", "curriculum SAC, training episodes"} <= set(_legend_labels(fig.axes[1]))
        held_out = next(line for line in fig.axes[1].lines if line.get_label() == "curriculum SAC, held-out")
        assert list(held_out.get_ydata()) == [e["summary"]["success_rate"] for e in data["evals"]]
        for ax in fig.axes:
            assert "lesson change" in _legend_labels(ax)
            names = {t.get_text(): t.get_position()[0] for t in ax.texts}
            assert {"lesson1", "lesson2"} <= set(names)
            low, high = ax.get_xlim()
            assert all(low <= x <= high for x in names.values())  # none cut off at an edge
    finally:
        plt.close(fig)


def test_track_figure_numbers_the_targets_and_labels_tolerances(passive_arm_reports):
    track = passive_arm_reports["track"]
    fig = figures.track_figure({"passive": track})
    try:
        assert fig._suptitle is not None and "3 targets" in fig._suptitle.get_text()
        assert [t[:3] for t in _panel_titles(fig, 3)] == ["(a)", "(b)", "(c)"]
        path = fig.axes[0]
        numbers = {t.get_text(): t.xy for t in path.texts}
        for number, segment in enumerate(track["segments"], start=1):
            np.testing.assert_allclose(numbers[str(number)], segment["target"])
        assert "targets, in order" in _legend_labels(path)
        assert "position tolerance (50 mm)" in _legend_labels(fig.axes[1])
        assert any(label.startswith("level head (90") for label in _legend_labels(fig.axes[2]))
        assert "next target" in _legend_labels(fig.axes[1])
    finally:
        plt.close(fig)


def test_track_figure_names_each_run_with_its_outcome_against_the_goal(passive_arm_reports):
    """One legend below the panels: each run by its name (plain SAC, not 'baseline'), its seed and
    budget where given, and how many targets it reached; the title states the goal."""
    track = passive_arm_reports["track"]
    reached = sum(bool(segment["success"]) for segment in track["segments"])
    fig = figures.track_figure({"baseline": track, "lookup": track}, notes={"baseline": "seed 2, 600k control steps"})
    try:
        runs = [t.get_text() for t in fig.legends[0].get_texts()]
        assert runs == [f"plain SAC (final lesson only) (seed 2, 600k control steps): {reached} of 3 reached",
                        f"lookup (no learning): {reached} of 3 reached"]
        assert not any(label in _legend_labels(ax) for ax in fig.axes for label in runs)
        assert "goal: each reached, within 50 mm and 5 deg of level" in fig._suptitle.get_text()
    finally:
        plt.close(fig)


def _seed_run(seed, curve, final, moving):
    """What compare_runs reads from one robostrich-train directory (numbers chosen so the
    means and bands are known exactly)."""
    evals = [{"env_steps": 1000 * (i + 1), "summary": {"success_rate": s, "position_error_median": 0.05 - 0.01 * s}}
             for i, s in enumerate(curve)]
    return {"seed": seed, "evals": evals, "final": {"heldout": {"success_rate": final},
                                                    "heldout_moving": {"success_rate": moving}}}


def test_seed_groups_figure_draws_the_mean_the_seed_band_and_every_seeds_final_rate():
    groups = {"A": [_seed_run(0, [0.2, 0.6, 1.0], 0.9, 0.8), _seed_run(1, [0.0, 0.4, 0.8, 0.9], 0.5, 0.4)],
              "B": [_seed_run(3, [0.5, 0.5, 0.5], 1.0, 1.0)]}
    fig = figures.seed_groups_figure(groups, lookup={"heldout": 0.95, "heldout_moving": 0.7},
                                     lesson_boundaries=[2000])
    success, error, finals = fig.axes[:3]
    mean_a = _line(success, "A (mean of 2 seeds)")
    np.testing.assert_allclose(mean_a.get_xdata(), [1000, 2000, 3000])  # the steps both seeds reached
    np.testing.assert_allclose(mean_a.get_ydata(), [0.1, 0.5, 0.9])
    band = success.collections[0].get_paths()[0].vertices[:, 1]
    assert band.min() == pytest.approx(0.0) and band.max() == pytest.approx(1.0)  # seed min..max
    assert _line(error, "A (mean of 2 seeds)").get_ydata()[0] == pytest.approx(0.049)
    assert _line(finals, "lookup, fixed start").get_ydata()[0] == 0.95
    rates = sorted(float(y) for c in finals.collections for y in c.get_offsets()[:, 1])
    assert rates == [0.4, 0.5, 0.8, 0.9, 1.0, 1.0]  # every seed, fixed and moving starts
    assert [t.get_text() for t in finals.get_xticklabels()] == ["A", "B"]
    assert finals.get_ylim()[0] < 0 < 1 < finals.get_ylim()[1]
    plt.close(fig)


def test_compare_runs_says_which_directory_is_not_a_run(tmp_path):
    tool = pathlib.Path(__file__).parents[1] / "tools" / "compare_runs.py"
    (tmp_path / "s0").mkdir()
    result = subprocess.run([sys.executable, str(tool), "--out", str(tmp_path / "x.png"), f"A={tmp_path}/s*"],
                            capture_output=True, text=True)
    assert result.returncode != 0 and "is not a finished robostrich-train run" in result.stderr
    assert not (tmp_path / "x.png").exists()
