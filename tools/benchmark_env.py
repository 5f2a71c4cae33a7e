"""Environment speed: `robostrich` lesson2 steps/s against raw mj_step of the same model.

    python tools/benchmark_env.py [--steps 5000]

Both run the same MJCF with the same 4 physics substeps per control step, so
the ratio is the cost of the dm_control wrapper, the task's observation and
reward, and our per-step checks.  The CPU may be shared, so both are run
interleaved ``--repeats`` times and the best rate of each is kept.
"""
import argparse
import os
import time

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from robostrich_suite import benchmarking, robostrich  # noqa: E402


def raw_steps_per_second(steps: int, actions: np.ndarray, episode_steps: int) -> float:
    """Plain MuJoCo on the same model with the same episodes: from the model's initial state
    (the task's fixed start), reset every ``episode_steps`` control steps as the environment is,
    so both simulate the same kind of states (a never-reset arm settles into other contacts)."""
    model = mujoco.MjModel.from_xml_string(robostrich.get_model_and_assets()[0])
    data = mujoco.MjData(model)
    substeps = int(round(robostrich.CONTROL_TIMESTEP / model.opt.timestep))
    start = time.perf_counter()
    for i in range(steps):
        if i % episode_steps == 0:
            mujoco.mj_resetData(model, data)
            mujoco.mj_forward(model, data)
        data.ctrl[:] = actions[i % len(actions)]
        mujoco.mj_step(model, data, substeps)
    return steps / (time.perf_counter() - start)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=5000)
    parser.add_argument("--task", default="lesson2")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    actions = benchmarking.random_actions("robostrich", args.task)
    episode_steps = benchmarking.episode_steps("robostrich", args.task)
    raw = wrapped = 0.0
    for _ in range(args.repeats):
        raw = max(raw, raw_steps_per_second(args.steps, actions, episode_steps))
        wrapped = max(wrapped, benchmarking.env_steps_per_second("robostrich", args.task,
                                                                 args.steps, actions))
    print(f"raw mj_step x4 : {raw:10.0f} control steps/s")
    print(f"robostrich/{args.task}: {wrapped:10.0f} env steps/s")
    print(f"ratio env/raw  : {wrapped / raw:10.3f}")


if __name__ == "__main__":
    main()
