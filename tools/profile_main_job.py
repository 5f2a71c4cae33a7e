"""Where the main job's minutes go: one curriculum run of robostrich-train, timed by what it does.

    python tools/profile_main_job.py [--steps 20000] [--json profile.json] [robostrich-train flags ...]

Runs `robostrich-train --no-baseline --workers 1` at ``--steps`` control steps (the main job's
lesson shares) with timers around what a run does, each second counted once, in the innermost:
stepping the environments (dm_control's ``Environment.step`` and ``reset``: physics and task),
acting (the policy on the host), the replay (adding and sampling), the learner (its update and
handing its parameters to the actor: JAX runs asynchronously, so the update's time shows where the
parameters are read), and the evaluations, periodic and final (all they spend, their own stepping
and acting included); building and compiling are the rest. Then the floor: the environment alone,
stepped with random inputs, and the control steps per second it allows. The minutes of a 200k run
are projected from the parts: training's scale with the control steps, the evaluations' and the
building's do not.
"""
import argparse
import contextlib
import sys
import tempfile
import time

import numpy as np
from dm_control.rl import control

from agents.actors import Actor
from agents.replay import ReplayBuffer
from agents.robostrich.domains import Domain
from agents.robostrich.evaluate import episodes
from agents.robostrich.train import command as training
from agents.robostrich.train.main_job import MAIN_JOB_STEPS
from agents.sac.learning import SACLearner
from robostrich_suite import atomic_files

PARTS = ("environment", "acting", "replay", "learner", "evaluation", "compiling")
TRAINING_PARTS = ("environment", "acting", "replay", "learner")  # they scale with the control steps


class ExclusiveTimers:
    """Seconds per part, each counted in the innermost part running (a stack of open parts); inside
    an evaluation everything counts as the evaluation (its stepping and acting do not scale with a
    run's control steps)."""

    def __init__(self):
        self.seconds = dict.fromkeys(PARTS, 0.0)
        self.calls = dict.fromkeys(PARTS, 0)
        self._stack = []  # (part, time it last resumed)
        self._wrapped = []  # (owner, attribute, original): put back by restore

    @contextlib.contextmanager
    def part(self, name: str):
        if any(open_part == "evaluation" for open_part, _ in self._stack):
            name = "evaluation"
        now = time.perf_counter()
        if self._stack:  # pause the enclosing part
            outer, since = self._stack[-1]
            self.seconds[outer] += now - since
        self._stack.append((name, now))
        self.calls[name] += 1
        try:
            yield
        finally:
            now = time.perf_counter()
            _, since = self._stack.pop()
            self.seconds[name] += now - since
            if self._stack:
                self._stack[-1] = (self._stack[-1][0], now)

    def wrap(self, owner, attribute: str, name: str, first: str = None) -> None:
        """Time every call of ``owner.attribute`` (a class's method or a module's function) as ``name``;
        its first call as ``first`` where given (the learner's, which compiles its update)."""
        original = getattr(owner, attribute)
        self._wrapped.append((owner, attribute, original))
        called = []

        def timed(*args, **kwargs):
            with self.part(first if first and not called else name):
                called.append(True)
                return original(*args, **kwargs)
        setattr(owner, attribute, timed)

    def restore(self) -> None:
        """Every wrapped method and function as it was."""
        for owner, attribute, original in reversed(self._wrapped):
            setattr(owner, attribute, original)
        self._wrapped.clear()


def environment_floor(steps: int) -> float:
    """Control steps per second of the main job's last lesson stepped alone with uniform random
    inputs (the moving neck a run steps, not a still one), drawn beforehand."""
    env = Domain("robostrich").make_environment("lesson3", 0)
    spec = env.action_spec()
    actions = np.random.default_rng(0).uniform(spec.minimum, spec.maximum, (steps, *spec.shape))
    env.reset()
    start = time.perf_counter()
    for action in actions:
        if env.step(action).last():
            env.reset()
    return steps / (time.perf_counter() - start)


def profile(steps: int, train_args: list) -> dict:
    timers = ExclusiveTimers()
    timers.wrap(SACLearner, "step", "learner", first="compiling")
    for owner, attribute, name in ((control.Environment, "step", "environment"),
                                   (control.Environment, "reset", "environment"),
                                   (Actor, "policy_action", "acting"), (Actor, "select_action", "acting"),
                                   (ReplayBuffer, "add", "replay"), (ReplayBuffer, "sample_stack", "replay"),
                                   (Actor, "update", "learner"),
                                   (episodes, "evaluate_heldout", "evaluation"),
                                   (episodes, "evaluate_heldout_moving", "evaluation"),
                                   (episodes, "evaluate_track", "evaluation")):
        timers.wrap(owner, attribute, name)
    try:
        with tempfile.TemporaryDirectory() as out:
            start = time.perf_counter()
            training.main(["--steps", str(steps), "--no-baseline", "--workers", "1", "--no-rerun", "--no-figures",
                           "--quiet", "--out", out, *train_args])
            total = time.perf_counter() - start
    finally:
        timers.restore()
    return {"steps": steps, "total_seconds": total, "seconds": timers.seconds, "calls": timers.calls,
            "other_seconds": total - sum(timers.seconds.values())}


def projected(result: dict, main_steps: int) -> dict:
    """Each part's seconds in a run of ``main_steps``: training's parts scale with the steps, the
    evaluations, the compile and the building do not."""
    scale = main_steps / result["steps"]
    parts = {part: result["seconds"][part] * (scale if part in TRAINING_PARTS else 1.0) for part in PARTS}
    return {**parts, "building, other": result["other_seconds"]}


def speed_record(result: dict, floor: float, main_steps: int) -> dict:
    """The measurement as a speed benchmark's record (tools/results_speed.py): the projected seconds
    of each part, and each against the environment alone over the same steps, measured in the same run."""
    parts, alone = projected(result, main_steps), main_steps / floor
    return {"benchmark": "speed",
            "description": f"one curriculum run of robostrich-train ({result['steps']:,} control steps, the main "
                           f"job's settings) timed by part and projected to {main_steps:,} steps, against the "
                           "environment alone (lesson 3 stepped with random inputs) over as many steps",
            "rates": [{"what": f"{part}, projected", "value": seconds, "unit": "s"} for part, seconds in parts.items()]
            + [{"what": "the environment alone", "value": floor, "unit": "control steps/s"}],
            "ratios": [{"what": "projected run / the environment alone", "value": sum(parts.values()) / alone}]
            + [{"what": f"{part} / the environment alone", "value": seconds / alone}
               for part, seconds in parts.items()]}


def report(result: dict, floor: float, main_steps: int) -> list:
    """The table's lines: each part's seconds and share, and the projection to ``main_steps``."""
    parts = projected(result, main_steps)
    lines = [f"one curriculum run of {result['steps']:,} control steps: {result['total_seconds']:.1f} s",
             f"| part | seconds | share | projected to {main_steps:,} steps (s) |", "|---|---|---|---|"]
    measured = {**result["seconds"], "building, other": result["other_seconds"]}
    for part, seconds in measured.items():
        lines.append(f"| {part} | {seconds:.1f} | {100 * seconds / result['total_seconds']:.0f} % | "
                     f"{parts[part]:.0f} |")
    lines.append(f"projected run: {sum(parts.values()) / 60:.1f} min; the environment alone (the floor): "
                 f"{floor:,.0f} control steps/s, {main_steps / floor:.0f} s for {main_steps:,} steps")
    return lines


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--steps", type=int, default=20_000, help="control steps of the profiled run (default: %(default)s)")
    parser.add_argument("--floor-steps", type=int, default=5_000,
                        help="control steps of the environment-alone measurement (default: %(default)s)")
    parser.add_argument("--json", default=None, help="also write the measurement here")
    args, train_args = parser.parse_known_args(argv)
    if args.steps < 1 or args.floor_steps < 1:
        parser.error("--steps and --floor-steps must be positive")
    result = profile(args.steps, train_args)
    floor = environment_floor(args.floor_steps)
    main_steps = MAIN_JOB_STEPS["robostrich"]
    print("\n".join(report(result, floor, main_steps)))
    result.update(floor_steps_per_second=floor, main_job_steps=main_steps, **speed_record(result, floor, main_steps),
                  command=" ".join(["python", "tools/profile_main_job.py", *(sys.argv[1:] if argv is None else argv)]))
    if args.json:
        atomic_files.write_json(args.json, result)
    return result


if __name__ == "__main__":
    main()
