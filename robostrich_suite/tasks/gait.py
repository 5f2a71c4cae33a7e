"""Leg joint targets for the A1-like quadruped: an open-loop trot and gait-file replay.

Every source answers the same question, ``joint_targets(t, trunk_height)``: the
12 joint targets (``quadruped.JOINT_NAMES`` order) at time ``t`` (a float or
an array of times, vectorised) with the trunk held ``trunk_height`` above the
ground (a :class:`TrunkHeightSchedule` varies it during an episode).  An optional
``stride_scale`` (4,) scales each foot's fore-aft travel, for steering.  The task
writes the targets into the leg servos every control step.

* :class:`TrotGait` -- diagonal pairs (FR+RL, FL+RR) half a cycle apart, duty
  0.5; in stance the foot moves linearly backwards by ``stride``, in swing it
  comes forward and is raised by ``lift * sin(pi u)``.  Foot positions become
  joint targets by two-link leg inverse kinematics (:func:`leg_ik`).
* :class:`Standing` -- feet under the hips (the standing quadruped);
* :class:`GaitReplay` -- recorded motor data (the paper replayed data from a
  real A1): samples linearly interpolated, looping.  A different trunk height
  is applied by moving every foot vertically (forward then inverse kinematics).

Gait file format (CSV, ``#`` starts a comment line)::

    time,FR_hip,FR_thigh,FR_calf,FL_hip,...,RL_calf
    0.000,0.0,0.93,-1.74,...

one header row naming the 13 columns in that order, then one row per sample:
time in seconds (strictly increasing, finite) and the 12 joint targets in
radians, each within its joint's range (``quadruped.JOINT_RANGES``).  The
sequence loops with period ``time[-1] - time[0]``, so the last row should
repeat the first (the shipped file ``data/a1_trot.csv`` does).  A malformed
file raises ``ValueError`` naming the line and column.

Regenerate the shipped file with
``robostrich-gait --out robostrich_suite/data/a1_trot.csv``
(:mod:`robostrich_suite.studies.gait`).
"""
from __future__ import annotations

import bisect
import csv
import dataclasses
import io
import os
import pathlib

import numpy as np

from robostrich_suite import atomic_files
from robostrich_suite.model import quadruped as quad
from robostrich_suite.model.legs import assemble, check_trunk_height, foot_depth, leg_fk, leg_ik

DATA_PATH = pathlib.Path(__file__).resolve().parents[1] / "data" / "a1_trot.csv"
MAX_FILE_BYTES = 100_000_000  # the shipped gait file is 30 kB
COLUMNS = ("time",) + quad.JOINT_NAMES
# Phase offset of each leg (FR, FL, RR, RL): diagonal pairs half a cycle apart.
TROT_PHASES = np.array([0.0, 0.5, 0.5, 0.0])


@dataclasses.dataclass
class TrotGait:
    """Open-loop trot (see the module doc); defaults walk the A1-like model at ~0.2 m/s."""
    frequency: float = 2.5  # Hz, gait cycles per second
    stride: float = 0.10  # m, foot travel relative to the hip during stance
    lift: float = 0.05  # m, swing foot height
    trunk_height: float = quad.STANDING_TRUNK_HEIGHT  # m, default height command
    duty: float = 0.5  # fraction of the cycle in stance

    def __post_init__(self):
        if not self.frequency > 0:
            raise ValueError(f"frequency must be positive, got {self.frequency}")
        if not 0 < self.duty < 1:
            raise ValueError(f"duty must be in (0, 1), got {self.duty}")
        if not 0 <= self.stride <= 0.2:
            raise ValueError(f"stride must be in [0, 0.2] m, got {self.stride}")
        if not 0 <= self.lift <= 0.1:
            raise ValueError(f"lift must be in [0, 0.1] m, got {self.lift}")
        check_trunk_height(self.trunk_height)

    def foot_positions(self, t, trunk_height=None):
        """Foot (x, z) from each hip, arrays of shape ``t.shape + (4,)``."""
        if trunk_height is not None:
            trunk_height = float(trunk_height) if np.ndim(trunk_height) == 0 else trunk_height
        height = self.trunk_height if trunk_height is None else trunk_height
        check_trunk_height(height)
        t = np.asarray(t, float)[..., None]
        phase = np.mod(t * self.frequency + TROT_PHASES, 1.0)
        stance = phase < self.duty
        u_stance = phase / self.duty
        u_swing = (phase - self.duty) / (1 - self.duty)
        half = self.stride / 2
        x = np.where(stance, half - self.stride * u_stance, -half + self.stride * u_swing)
        raise_ = np.where(stance, 0.0, self.lift * np.sin(np.pi * np.clip(u_swing, 0, 1)))
        z = -foot_depth(np.asarray(height, float)[..., None]) + raise_
        return x, z

    def joint_targets(self, t, trunk_height=None, stride_scale=None) -> np.ndarray:
        """Joint targets; ``stride_scale`` (4,) scales each foot's fore-aft travel (steering)."""
        x, z = self.foot_positions(t, trunk_height)
        if stride_scale is not None:
            x = x * stride_scale
        return assemble(*leg_ik(x, z))

    @property
    def period(self) -> float:
        return 1.0 / self.frequency


@dataclasses.dataclass
class Standing:
    """Feet under the hips at the commanded trunk height: the standing quadruped."""
    trunk_height: float = quad.STANDING_TRUNK_HEIGHT

    def joint_targets(self, t, trunk_height=None, stride_scale=None) -> np.ndarray:
        height = self.trunk_height if trunk_height is None else trunk_height
        check_trunk_height(height)
        shape = np.shape(t) + (4,)
        hip, knee = leg_ik(np.zeros(shape), -np.broadcast_to(foot_depth(height), np.shape(t))[
            ..., None] * np.ones(shape))
        return assemble(hip, knee)


class GaitReplay:
    """Recorded joint targets over time, linearly interpolated and looped."""

    def __init__(self, times, targets):
        times = np.asarray(times, float)
        targets = np.asarray(targets, float)
        validate(times, targets)
        self.times, self.targets = times, targets
        self.period = float(times[-1] - times[0])
        # Depth of the stance feet under the hips: the trunk height the data was recorded at.
        _, foot_z = leg_fk(targets[:, 1::3], targets[:, 2::3])
        self.recorded_trunk_height = float(np.max(-foot_z) + quad.FOOT_RADIUS)
        # Targets and foot positions side by side, interpolated together: (n, 12 + 4 + 4).
        self._table = np.concatenate([targets, *leg_fk(targets[:, 1::3], targets[:, 2::3])],
                                     axis=1)
        self._t0, self._time_list = float(times[0]), times.tolist()

    @classmethod
    def from_file(cls, path=DATA_PATH) -> "GaitReplay":
        return cls(*read_gait_file(path))

    def _interpolate(self, table, t):
        if np.ndim(t) == 0:  # the per-step path: one bisection, no array temporaries
            local = self._t0 + (float(t) - self._t0) % self.period
            upper = min(max(bisect.bisect_right(self._time_list, local), 1), len(self.times) - 1)
            t0, t1 = self._time_list[upper - 1], self._time_list[upper]
            below = table[upper - 1]
            return below + (table[upper] - below) * ((local - t0) / (t1 - t0))
        t = np.asarray(t, float)
        local = self.times[0] + np.mod(t - self.times[0], self.period)
        upper = np.clip(np.searchsorted(self.times, local, side="right"), 1, len(self.times) - 1)
        t0, t1 = self.times[upper - 1], self.times[upper]
        weight = ((local - t0) / (t1 - t0))[..., None]
        return table[upper - 1] * (1 - weight) + table[upper] * weight

    def raw_targets(self, t) -> np.ndarray:
        """Targets at time(s) ``t`` as recorded: interpolated, looped."""
        return self._interpolate(self.targets, t)

    def joint_targets(self, t, trunk_height=None, stride_scale=None) -> np.ndarray:
        """Recorded targets at ``t``; for another trunk height or a stride scale the
        recorded foot positions (interpolated) are moved and turned back into angles."""
        if trunk_height is None and stride_scale is None:
            return self.raw_targets(t)
        row = self._interpolate(self._table, t)
        targets, x, z = row[..., :12], row[..., 12:16], row[..., 16:]
        if trunk_height is not None:
            trunk_height = float(trunk_height) if np.ndim(trunk_height) == 0 else trunk_height
            check_trunk_height(trunk_height)
            z = z - (np.asarray(trunk_height) - self.recorded_trunk_height)[..., None]
        if stride_scale is not None:
            x = x * stride_scale
        targets[..., 1::3], targets[..., 2::3] = leg_ik(x, z)
        return targets


@dataclasses.dataclass
class TrunkHeightSchedule:
    """Piecewise-linear trunk height command over time, held after the last knot."""
    times: tuple = (0.0,)
    heights: tuple = (quad.STANDING_TRUNK_HEIGHT,)

    def __post_init__(self):
        times, heights = np.asarray(self.times, float), np.asarray(self.heights, float)
        if times.shape != heights.shape or times.ndim != 1 or len(times) == 0:
            raise ValueError("times and heights must be 1-D sequences of the same, non-zero length")
        if not np.all(np.isfinite(times)):
            raise ValueError(f"schedule times must be finite, got {self.times}")
        if np.any(np.diff(times) <= 0):
            raise ValueError(f"schedule times must increase strictly, got {self.times}")
        check_trunk_height(heights)
        self._times, self._heights = times, heights

    def __call__(self, t):
        return np.interp(t, self._times, self._heights)


# --- gait files ----------------------------------------------------------------
def validate(times: np.ndarray, targets: np.ndarray, rows=None) -> None:
    """Raise ``ValueError`` for a gait sequence that cannot be replayed.

    ``rows`` gives the file line of each sample for the message.
    """
    rows = list(range(1, len(times) + 1)) if rows is None else rows
    if targets.ndim != 2 or targets.shape[1] != 12 or len(times) != len(targets):
        raise ValueError(f"gait needs (n,) times and (n, 12) joint targets, got {times.shape} "
                         f"and {targets.shape}")
    if len(times) < 2:
        raise ValueError(f"a gait needs at least 2 samples, got {len(times)}")
    for j, column in enumerate([times, *targets.T]):
        bad = np.flatnonzero(~np.isfinite(column))
        if bad.size:
            raise ValueError(f"line {rows[bad[0]]}, column {j + 1} ({COLUMNS[j]}): "
                             f"value {column[bad[0]]} is not finite")
    steps = np.diff(times)
    bad = np.flatnonzero(steps <= 0)
    if bad.size:
        i = bad[0] + 1
        raise ValueError(f"line {rows[i]}, column 1 (time): time {times[i]} does not increase "
                         f"(previous sample {times[i - 1]}); times must increase strictly")
    low, high = quad.JOINT_RANGES.T
    outside = (targets < low) | (targets > high)
    if outside.any():
        i, j = np.argwhere(outside)[0]
        raise ValueError(f"line {rows[i]}, column {j + 2} ({COLUMNS[j + 1]}): angle "
                         f"{targets[i, j]} rad is outside the joint range [{low[j]}, {high[j]}]")


def read_gait_file(path) -> tuple[np.ndarray, np.ndarray]:
    """Read and validate a gait CSV (module doc); returns ``(times, targets)``."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"a gait must be a gait file path (str or os.PathLike), a TrotGait, a GaitReplay "
                        f"or an object with joint_targets(t, trunk_height, stride_scale); "
                        f"got {type(path).__name__} {path!r}")
    path = pathlib.Path(path)
    rows, values = [], []
    header_seen = False
    if not path.is_file():
        raise ValueError(f"{path}: no such gait file")
    if path.stat().st_size > MAX_FILE_BYTES:
        raise ValueError(f"{path}: {path.stat().st_size} bytes, more than a gait file's {MAX_FILE_BYTES}")
    try:  # utf-8-sig: a byte-order mark (spreadsheet exports) is not part of 'time'
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as error:
        raise ValueError(f"{path}: not a text (UTF-8) gait file: byte {error.start} cannot be decoded") from None
    if "\0" in text:
        raise ValueError(f"{path}: not a text gait file (it contains NUL bytes)")
    with io.StringIO(text, newline="") as handle:
        reader = csv.reader(handle)
        for line_number, row in enumerate(_rows(reader, path), start=1):
            if not row or not "".join(row).strip() or row[0].lstrip().startswith("#"):
                continue
            cells = [cell.strip() for cell in row]
            if len(cells) != len(COLUMNS):
                raise ValueError(f"{path}: line {line_number}: {len(cells)} columns, expected "
                                 f"{len(COLUMNS)} (time + 12 joint targets)")
            if not header_seen:
                header_seen = True
                if tuple(cells) != COLUMNS:  # the header names the columns: required, so a file
                    # whose columns are in another order cannot be replayed silently
                    wrong = next(i for i, (a, b) in enumerate(zip(cells, COLUMNS)) if a != b)
                    raise ValueError(f"{path}: line {line_number}, column {wrong + 1}: header "
                                     f"{cells[wrong]!r}, expected {COLUMNS[wrong]!r} (the first row "
                                     f"must name the columns: {','.join(COLUMNS)})")
                continue
            try:
                numbers = [float(cell) for cell in cells]
            except ValueError:
                column = next(i for i, c in enumerate(cells) if not _is_float(c))
                raise ValueError(f"{path}: line {line_number}, column {column + 1}: "
                                 f"{cells[column]!r} is not a number") from None
            rows.append(line_number)
            values.append(numbers)
    if not values:
        raise ValueError(f"{path}: no samples")
    data = np.array(values)
    try:
        validate(data[:, 0], data[:, 1:], rows)
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from None
    return data[:, 0], data[:, 1:]


def _rows(reader, path):
    """The rows of a csv reader, its own errors (a field over csv's size limit, a NUL) as a
    ValueError naming the file and line."""
    while True:
        try:
            yield next(reader)
        except StopIteration:
            return
        except csv.Error as error:
            raise ValueError(f"{path}: line {reader.line_num}: {error}") from None


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def write_gait_file(path, times, targets, comment: str | None = None) -> None:
    """Write ``times`` (n,) and ``targets`` (n, 12) in the gait CSV format."""
    times, targets = np.asarray(times, float), np.asarray(targets, float)
    validate(times, targets)
    out = io.StringIO()
    if comment:
        for line in comment.splitlines():
            out.write(f"# {line}\n")
    out.write(",".join(COLUMNS) + "\n")
    for t, row in zip(times, targets):
        out.write(",".join([f"{t:.6f}"] + [f"{v:.6f}" for v in row]) + "\n")
    atomic_files.write_text(path, out.getvalue())
