"""Environment speed: `robostrich` lesson2 steps/s against raw mj_step of the same model.

    python tools/benchmark_env.py [--steps 1000] [--rounds 21]

Both run the same MJCF with the same 4 physics substeps per control step, so
the ratio is the cost of the dm_control wrapper, the task's observation and
reward, and our per-step checks.  The CPU's speed drifts by several per cent
from second to second (another process, its clock), so the two alternate in
short rounds of ``--steps`` control steps and the ratio reported is the
median of the rounds' ratios (each round's two halves ran within a second of
each other), with its interquartile range.
"""
import argparse
import os
import time

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from robostrich_suite import benchmarking, robostrich  # noqa: E402


class RawLoop:
    """Plain MuJoCo on the same model with the same episodes: from the model's initial state
    (the task's fixed start), reset every ``episode_steps`` control steps as the environment is,
    so both simulate the same kind of states (a never-reset arm settles into other contacts)."""

    def __init__(self, actions: np.ndarray, episode_steps: int):
        self.model = mujoco.MjModel.from_xml_string(robostrich.get_model_and_assets()[0])
        self.data = mujoco.MjData(self.model)
        self.substeps = int(round(robostrich.CONTROL_TIMESTEP / self.model.opt.timestep))
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


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=1000, help="control steps per round and loop")
    parser.add_argument("--rounds", type=int, default=21)
    parser.add_argument("--task", default="lesson2")
    args = parser.parse_args(argv)
    actions = benchmarking.random_actions("robostrich", args.task)
    raw = RawLoop(actions, benchmarking.episode_steps("robostrich", args.task))
    wrapped = benchmarking.EnvLoop("robostrich", args.task, actions)
    raw.run(args.steps), wrapped.run(args.steps)  # warm caches and allocations
    raw_seconds, env_seconds = [], []
    for _ in range(args.rounds):
        raw_seconds.append(raw.run(args.steps))
        env_seconds.append(wrapped.run(args.steps))
    ratios = np.array(raw_seconds) / np.array(env_seconds)
    low, median, high = np.percentile(ratios, [25, 50, 75])
    print(f"raw mj_step x{raw.substeps} : {args.steps / min(raw_seconds):10.0f} control steps/s (best round)")
    print(f"robostrich/{args.task}: {args.steps / min(env_seconds):10.0f} env steps/s (best round)")
    print(f"ratio env/raw  : {median:10.3f} (median of {args.rounds} rounds; quartiles {low:.3f}-{high:.3f})")


if __name__ == "__main__":
    main()
