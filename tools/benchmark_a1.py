"""Environment speed: `robostrich_a1` lesson4 steps/s against raw mj_step of the same model.

    python tools/benchmark_a1.py [--steps 2000] [--task lesson4] [--json speed_a1.json]

All runs use the same MJCF and the same 4 physics substeps per control step:

* raw: ``mujoco.mj_step`` with the tendon inputs and a standing pose written to ``ctrl``;
* raw + gait: as raw, plus the gait's 12 joint targets computed in numpy each step;
* env: ``robostrich_suite.load("robostrich_a1", task).step`` (gait, steering, checks,
  observation and reward).

The printed ratios are the cost of the wrapper (env/raw) and of the gait alone.  The
CPU is shared, so the three are run interleaved ``--repeats`` times and the best
rate of each is kept.  Then where an env step's time goes, so that the next lever shows:
one more env loop with a timer around each part dm_control calls (the physics' substeps,
the task's ``before_step``, which sets the gait's leg targets, its ``after_step``, the
observation and the reward), the rest being dm_control's own step and the resets.
"""
import argparse
import collections
import os
import sys
import time

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from robostrich_suite import speed_benchmarks, robostrich_a1  # noqa: E402
from robostrich_suite.model import quadruped  # noqa: E402
from robostrich_suite.tasks import gait, quadruped_tasks  # noqa: E402


def _raw_model():
    model = mujoco.MjModel.from_xml_string(robostrich_a1.get_model_and_assets()[0])
    data = mujoco.MjData(model)
    physics = robostrich_a1.Physics.from_xml_string(robostrich_a1.get_model_and_assets()[0])
    physics.place_standing()
    data.qpos[:] = physics.data.qpos
    arm = physics.arm_indices.actuators
    legs = physics._robot()["leg_actuators"]
    return model, data, arm, legs


def raw_steps_per_second(steps: int, actions: np.ndarray, with_gait: bool = False) -> float:
    model, data, arm, legs = _raw_model()
    substeps = int(round(robostrich_a1.CONTROL_TIMESTEP / model.opt.timestep))
    source = gait.GaitReplay.from_file()
    data.ctrl[legs] = quadruped.STANDING_TARGETS
    start = time.perf_counter()
    for i in range(steps):
        data.ctrl[arm] = actions[i % len(actions)]
        if with_gait:
            data.ctrl[legs] = source.joint_targets(data.time, 0.28)
        mujoco.mj_step(model, data, substeps)
    return steps / (time.perf_counter() - start)


PARTS = {"physics": ("physics", "step"), "before_step (gait)": ("task", "before_step"),
         "after_step": ("task", "after_step"), "observation": ("task", "get_observation"),
         "reward": ("task", "get_reward")}


def step_parts(task: str, steps: int, actions: np.ndarray) -> dict:
    """Share of an env step's time per part (PARTS, then "other": dm_control's step and the resets)."""
    loop = speed_benchmarks.EnvLoop("robostrich_a1", task, actions)
    seconds = collections.Counter()
    for part, (owner, method) in PARTS.items():
        instance = loop.env.physics if owner == "physics" else loop.env.task
        original = getattr(instance, method)

        def timed(*args, _original=original, _part=part, **kwargs):
            start = time.perf_counter()
            try:
                return _original(*args, **kwargs)
            finally:
                seconds[_part] += time.perf_counter() - start
        setattr(instance, method, timed)  # dm_control looks the method up on the instance
    total = loop.run(steps)
    shares = {part: seconds[part] / total for part in PARTS}
    return {**shares, "other": 1.0 - sum(shares.values())}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0], allow_abbrev=False)
    parser.add_argument("--steps", type=int, default=2000, help="control steps per loop and repeat")
    parser.add_argument("--repeats", type=int, default=3, help="times the three loops run in turn (best kept)")
    parser.add_argument("--task", default="lesson4", choices=list(robostrich_a1.SUITE), help="the task to step")
    parser.add_argument("--json", default=None, help="also write the rates and ratios here (a results record's input)")
    args = parser.parse_args(argv)
    actions = speed_benchmarks.random_actions("robostrich_a1", args.task)
    raw = raw_gait = wrapped = 0.0
    for _ in range(args.repeats):
        raw = max(raw, raw_steps_per_second(args.steps, actions))
        raw_gait = max(raw_gait, raw_steps_per_second(args.steps, actions, with_gait=True))
        wrapped = max(wrapped, speed_benchmarks.env_steps_per_second("robostrich_a1", args.task,
                                                                 args.steps, actions))
    print(f"raw mj_step x4        : {raw:10.0f} control steps/s")
    print(f"raw + gait targets    : {raw_gait:10.0f} control steps/s")
    print(f"robostrich_a1/{args.task:8s}: {wrapped:10.0f} control steps/s "
          f"(including resets every {quadruped_tasks.LESSON4_TIME_LIMIT:g} s)")
    print(f"ratio env/raw         : {wrapped / raw:10.3f}")
    print(f"ratio (raw+gait)/raw  : {raw_gait / raw:10.3f}")
    parts = step_parts(args.task, args.steps, actions)
    print("where an env step's time goes: " + ", ".join(f"{part} {share:.0%}" for part, share in parts.items()))
    if args.json:
        speed_benchmarks.write_report(
            args.json, __file__, argv if argv is not None else sys.argv[1:],
            f"robostrich_a1/{args.task} against raw mj_step of the same model, the loops in turn "
            f"{args.repeats} times for {args.steps} control steps, the best rate of each kept",
            [speed_benchmarks.rate("raw mj_step x4", raw, "control steps/s"),
             speed_benchmarks.rate("raw mj_step x4 + the gait's joint targets", raw_gait, "control steps/s"),
             speed_benchmarks.rate(f"robostrich_a1/{args.task}", wrapped, "control steps/s")],
            [speed_benchmarks.ratio(f"robostrich_a1/{args.task} / raw mj_step", wrapped / raw),
             speed_benchmarks.ratio("raw + gait / raw mj_step", raw_gait / raw),
             *(speed_benchmarks.ratio(f"share of an env step: {part}", share) for part, share in parts.items())])
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
