"""Environment speed: `robostrich` lesson2 steps/s against raw mj_step of the same model.

    python tools/benchmark_env.py [--steps 1000] [--rounds 21] [--json speed_env.json]

All run the same MJCF with the same 4 physics substeps per control step, so
the ratio is the cost of the dm_control wrapper, the task's observation and
reward, and our per-step checks.  A bare dm_control environment of the same
model (a task that only writes the action and returns the joint positions)
runs beside them: the floor any dm_control task stands on.  The CPU's speed
drifts by several per cent from second to second (another process, its
clock), so the loops alternate in short rounds of ``--steps`` control steps
and each ratio reported is the median of the rounds' ratios (each round's
parts ran within a second of each other), with its interquartile range.
"""
import argparse
import os
import sys
import time

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
from dm_control import mujoco as dm_mujoco  # noqa: E402
from dm_control.rl import control  # noqa: E402
from dm_control.suite import base  # noqa: E402

from robostrich_suite import speed_benchmarks, robostrich  # noqa: E402
from robostrich_suite.tasks import conventions, lessons  # noqa: E402


class RawLoop:
    """Plain MuJoCo on the same model with the same episodes: from the model's initial state
    (the task's fixed start), reset every ``episode_steps`` control steps as the environment is,
    so both simulate the same kind of states (a never-reset arm settles into other contacts)."""

    def __init__(self, actions: np.ndarray, episode_steps: int):
        self.model = mujoco.MjModel.from_xml_string(robostrich.get_model_and_assets()[0])
        self.data = mujoco.MjData(self.model)
        self.substeps = int(round(conventions.CONTROL_TIMESTEP / self.model.opt.timestep))
        self.actions, self.episode_steps, self.count = actions, episode_steps, 0

    def run(self, steps: int) -> float:
        """Seconds for ``steps`` control steps."""
        model, data, actions = self.model, self.data, self.actions
        start = time.perf_counter()
        for i in range(self.count, self.count + steps):
            if i % self.episode_steps == 0:
                mujoco.mj_resetData(model, data)
                mujoco.mj_forward(model, data)
            data.ctrl[:] = actions[i % len(actions)]
            mujoco.mj_step(model, data, self.substeps)
        self.count += steps
        return time.perf_counter() - start


class BareTask(base.Task):
    """The least a dm_control task does: write the action, return one observation, a reward."""

    def initialize_episode(self, physics):
        pass

    def before_step(self, action, physics):
        physics.data.ctrl[:] = action

    def get_observation(self, physics):
        return {"joint_positions": physics.data.qpos.copy()}

    def get_reward(self, physics):
        return 0.0


def bare_loop(actions: np.ndarray) -> speed_benchmarks.EnvLoop:
    """A plain dm_control environment of the same model with ``BareTask``: the same control
    step and episodes (2 s from the model's initial state) as the lesson's."""
    physics = dm_mujoco.Physics.from_xml_string(robostrich.get_model_and_assets()[0])
    env = control.Environment(physics, BareTask(random=0), time_limit=lessons.LESSON_TIME_LIMIT,
                              control_timestep=conventions.CONTROL_TIMESTEP)
    return speed_benchmarks.EnvLoop.of(env, actions)


def round_ratio(raw_seconds, seconds) -> tuple:
    """(lower quartile, median, upper quartile) of the rounds' speed ratios against raw."""
    return tuple(np.percentile(np.array(raw_seconds) / np.array(seconds), [25, 50, 75]))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0], allow_abbrev=False)
    parser.add_argument("--steps", type=int, default=1000, help="control steps per round and loop")
    parser.add_argument("--rounds", type=int, default=21, help="rounds of the three loops in turn")
    parser.add_argument("--task", default="lesson2", help="the robostrich task to step")
    parser.add_argument("--json", default=None, help="also write the rates and ratios here (a results record's input)")
    args = parser.parse_args(argv)
    actions = speed_benchmarks.random_actions("robostrich", args.task)
    raw = RawLoop(actions, speed_benchmarks.episode_steps("robostrich", args.task))
    bare = bare_loop(actions)
    wrapped = speed_benchmarks.EnvLoop("robostrich", args.task, actions)
    loops = {"raw": raw, "bare": bare, "env": wrapped}
    seconds = {name: [] for name in loops}
    for loop in loops.values():
        loop.run(args.steps)  # warm caches and allocations
    for _ in range(args.rounds):
        for name, loop in loops.items():
            seconds[name].append(loop.run(args.steps))
    best = {name: args.steps / min(times) for name, times in seconds.items()}
    print(f"raw mj_step x{raw.substeps} : {best['raw']:10.0f} control steps/s (best round)")
    print(f"bare dm_control: {best['bare']:10.0f} control steps/s (best round)")
    print(f"robostrich/{args.task}: {best['env']:10.0f} control steps/s (best round)")
    ratios = {name: round_ratio(seconds["raw"], seconds[name]) for name in ("bare", "env")}
    for name, (low, median, high) in ratios.items():
        print(f"ratio {name + '/raw':9s}: {median:10.3f} (median of {args.rounds} rounds; "
              f"quartiles {low:.3f}-{high:.3f})")
    if args.json:
        speed_benchmarks.write_report(
            args.json, __file__, argv if argv is not None else sys.argv[1:],
            f"robostrich/{args.task} against raw mj_step of the same model and episodes, the three loops "
            f"alternating in {args.rounds} rounds of {args.steps} control steps; each ratio the median of "
            "the rounds' ratios [quartiles], each rate the best round",
            [speed_benchmarks.rate(f"raw mj_step x{raw.substeps}", best["raw"], "control steps/s"),
             speed_benchmarks.rate("bare dm_control environment", best["bare"], "control steps/s"),
             speed_benchmarks.rate(f"robostrich/{args.task}", best["env"], "control steps/s")],
            [speed_benchmarks.ratio("bare dm_control / raw mj_step", ratios["bare"][1], ratios["bare"][0],
                                ratios["bare"][2]),
             speed_benchmarks.ratio(f"robostrich/{args.task} / raw mj_step", ratios["env"][1], ratios["env"][0],
                                ratios["env"][2])])
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
