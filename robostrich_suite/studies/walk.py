"""The walk tool: the quadruped's gait with scripted tendons, as a recording and a figure.

    robostrich-walk [--task head_stabilize] [--tendons zero|sine] [--gait trot|FILE] --out out/walk

writes ``out/walk/walk.rrd`` (the robot over sim time, the head's path, the series
below as scalars) and ``out/walk/walk.png`` (trunk and head height, speeds, the head's
distance ahead of the trunk, head attitude and trunk pitch over time), so a user
sees the perturbation the arm gets from walking.  ``--out`` is a directory, as for
every ``robostrich-*`` command.
"""
from __future__ import annotations

import argparse
import collections
import pathlib

import numpy as np

import robostrich_suite
from robostrich_suite import cli as cli_lib
from robostrich_suite import outputs
from robostrich_suite import progress as progress_lib
from robostrich_suite import physics as physics_lib
from robostrich_suite import rerun_blueprint, rerun_log
from robostrich_suite.robostrich_a1 import CONTROL_TIMESTEP, SUITE
from robostrich_suite.tasks import gait as gait_lib
from robostrich_suite.studies import walk_figure


# What walk.rrd opens on: the robot beside the series a reader of Fig. 9 compares (plots/ holds more).
WALK_SERIES = (("Heights (m)", ["plots/trunk_height", "plots/height_command", "plots/head_height"]),
               ("Speeds (m/s)", ["plots/trunk_speed", "plots/head_speed", "plots/head_vertical_speed"]),
               ("Head attitude, trunk pitch (deg)", ["plots/head_attitude", "plots/trunk_pitch"]))


def walk_blueprint():
    """The layout walk.rrd opens in: the quadruped (camera left to Rerun) beside WALK_SERIES."""
    return rerun_blueprint.robot_and_series(WALK_SERIES, robot="Quadruped, arm and head path")


def scripted_tendons(kind: str, control_range: np.ndarray, dorsal: int):
    """Tendon input as a function of time: ``zero``, or ``sine`` (a slow nod: the ventral
    tendons contract together at 0.5 Hz up to 30 % of their range, the dorsal one, action
    index ``dorsal`` (:func:`physics.dorsal_index`), pays out)."""
    low, high = control_range.T
    if kind == "zero":
        return lambda t: np.zeros(len(low))
    if kind == "sine":
        def nod(t):
            level = 0.15 * (1 - np.cos(2 * np.pi * 0.5 * t))
            action = level * high
            action[dorsal] = level * low[dorsal]
            return action
        return nod
    raise ValueError(f"unknown tendon script {kind!r}; use 'zero' or 'sine'")


def record_walk(task_name: str = "head_stabilize", seconds: float = 10.0, tendons: str = "zero",
                gait=None, rrd_path=None, seed: int = 0, progress: bool = False) -> dict:
    """Run ``task_name`` with scripted tendons; returns the time series (and writes an .rrd),
    with a progress bar over the steps if ``progress``.

    Series: ``time``, ``trunk_height``, ``height_command``, ``head_height``,
    ``trunk_speed`` (forward), ``head_speed`` (3-D), ``head_vertical_speed``,
    ``head_forward_distance`` (from the trunk centre), ``head_attitude``, ``trunk_pitch``,
    and the task's target: ``target_forward`` (P_d, ahead of the trunk centre) and
    ``target_height`` (above the ground).
    """
    task_kwargs = dict(random=seed, time_limit=seconds)
    if gait is not None:
        task_kwargs["gait"] = gait
    env = robostrich_suite.load("robostrich_a1", task_name, task_kwargs=task_kwargs)
    env.reset()
    physics = env.physics
    script = scripted_tendons(tendons, physics.arm_control_range(),
                              physics_lib.dorsal_index(physics.model))
    steps = int(round(seconds / CONTROL_TIMESTEP))
    if rrd_path is None:
        return _walk(env, script, steps, None, progress)
    with rerun_log.recording("robostrich_a1_walk", pathlib.Path(rrd_path), blueprint=walk_blueprint()) as rec:
        rerun_log.log_geometry(rec, physics)
        return _walk(env, script, steps, rec, progress)


def _walk(env, script, steps: int, rec, progress: bool) -> dict:
    """`steps` control steps of `script`'s tendon inputs: the series of record_walk, logged to `rec`."""
    with progress_lib.bar(progress, total=steps, desc="walk", unit="step", mininterval=0.5) as bar:
        return _walk_steps(env, script, steps, rec, bar)


def _walk_steps(env, script, steps: int, rec, bar) -> dict:
    physics = env.physics
    series = collections.defaultdict(list)
    head_path = []
    for i in range(steps):
        cli_lib.raise_if_interrupted()  # a library may have swallowed Ctrl-C's KeyboardInterrupt
        t = env.task.episode_time(physics)
        step = env.step(script(t))
        t = env.task.episode_time(physics)
        head = physics.head_position()
        head_velocity = physics.head_velocity()
        trunk_axis_x = physics.data.xmat[physics._robot()["trunk"]].reshape(3, 3)[:, 0]
        target_forward, target_height = env.task.target_position  # trunk frame: ahead, up
        values = dict(
            time=t, trunk_height=physics.trunk_height(),
            height_command=env.task.trunk_height_command(physics), head_height=head[2],
            trunk_speed=physics.to_trunk_frame(physics.trunk_velocity(), velocity=True)[0],
            head_speed=float(np.linalg.norm(head_velocity)),
            head_vertical_speed=head_velocity[2],
            head_forward_distance=physics.to_trunk_frame(head)[0],
            head_attitude=physics.head_attitude(),
            trunk_pitch=float(np.degrees(np.arcsin(np.clip(-trunk_axis_x[2], -1, 1)))),
            target_forward=target_forward, target_height=target_height)
        for key, value in values.items():
            series[key].append(float(value))
        if rec is not None:
            head_path.append(head)
            rerun_log.set_sim_time(rec, t)
            rerun_log.log_body_poses(rec, physics)
            rerun_log.log_scalars(rec, "plots", {k: v for k, v in values.items() if k != "time"})
            if i % 10 == 0:
                rerun_log.log_path(rec, "world/head_path", head_path)
        if bar is not None:
            bar.update()
        if step.last():
            break
    return {key: np.array(value) for key, value in series.items()}


def _at_least_one_step(text: str) -> float:
    try:
        seconds = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid number: {text!r}") from None
    if not CONTROL_TIMESTEP <= seconds <= cli_lib.MAX_SECONDS:  # also NaN
        raise argparse.ArgumentTypeError(f"must be from one control step ({CONTROL_TIMESTEP} s) to "
                                         f"{cli_lib.MAX_SECONDS:g} s, got {text}")
    return seconds


def out_directory_problem(out: pathlib.Path) -> str | None:
    """Why ``out`` cannot be the output directory, or None.  Before, ``--out`` was a file
    stem (``--out out/walk`` wrote out/walk.png); a stem still works (it is now the
    directory), but a file name with the tool's suffixes, or an existing file, is refused."""
    if out.suffix.lower() in (".png", ".rrd"):
        return (f"'{out}' names a file; --out is a directory (writes DIR/walk.png and "
                f"DIR/walk.rrd), e.g. --out {out.with_suffix('')}")
    if out.exists() and not out.is_dir():
        return f"'{out}' is a file; --out is a directory (writes DIR/walk.png and DIR/walk.rrd)"
    return None


def main(argv=None) -> None:
    """The walk tool: trot with scripted tendons, write a Rerun recording and a PNG."""
    parser = cli_lib.Parser(
        description="Walk the quadruped with the arm on it; write walk.rrd and walk.png under --out "
                    "(trunk and head height, speed and attitude over time).")
    parser.add_argument("--task", default="head_stabilize", choices=list(SUITE),
                        help="robostrich_a1 task whose gait and trunk heights to run (default: %(default)s)")
    parser.add_argument("--seconds", type=_at_least_one_step, default=12.0,
                        help="simulated time, at least one control step (default: %(default)s)")
    parser.add_argument("--tendons", default="zero", choices=["zero", "sine"],
                        help="scripted tendon input (zero: the passive neck; default: %(default)s)")
    parser.add_argument("--gait", default=None,
                        help="gait file (CSV, see robostrich_suite.tasks.gait) or 'trot' for the "
                             "generator; default: the shipped file")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/walk"),
                        help="output directory: writes OUT/walk.rrd and OUT/walk.png "
                             "(default: %(default)s)")
    parser.add_argument("--no-rerun", "--no-rrd", dest="no_rrd", action="store_true", help="no .rrd recording")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--seed", type=cli_lib.seed, default=0,
                        help="random seed of the episode (default: %(default)s)")
    args = parser.parse_args(argv)
    outputs.check_directory(args.out)
    problem = out_directory_problem(args.out)
    if problem:
        parser.error(f"argument --out: {problem}")
    gait = gait_lib.TrotGait() if args.gait == "trot" else args.gait
    rrd = None if args.no_rrd else args.out / "walk.rrd"
    series = record_walk(args.task, args.seconds, args.tendons, gait, rrd, args.seed, progress=not args.no_progress)
    png = args.out / "walk.png"
    walk_figure.plot_walk(series, png, f"robostrich_a1/{args.task}, tendons: {args.tendons}")
    walked = np.sum(series["trunk_speed"]) * CONTROL_TIMESTEP
    print(f"{len(series['time'])} steps, {series['time'][-1]:.2f} s: "
          f"mean forward speed {walked / series['time'][-1]:.3f} m/s, "
          f"head height {series['head_height'].mean():.3f} +- {series['head_height'].std():.3f} m, "
          f"head attitude {series['head_attitude'].mean():.1f} +- "
          f"{series['head_attitude'].std():.1f} deg")
    if rrd is not None:
        print(f"wrote {rrd}")
    print(f"wrote {png}")


def cli(argv=None) -> int:
    """Console script `robostrich-walk`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-walk", argv)


if __name__ == "__main__":
    import sys
    sys.exit(cli())
