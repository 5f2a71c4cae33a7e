"""The paper's movement tests (Sec. 4.3, Figs. 3-5): rolling and lever patterns.

Scripted tendon inputs on the arm on its immobile frame.  The dorsal tendon is held
while the ventral tendons are ramped: **rolling** contracts them one after another,
caudal to cranial, so the bend travels along the neck; **lever** contracts them
together, to the amplitude at which the head travels as far (``match_lever_amplitude``).
The defaults (:class:`MovementConfig`: the tasks' arm, whose ventral tendons are slips,
dorsal input held) are the setting in which the paper's difference shows (rolling keeps
the attitude smaller than the lever); on the routing with every ventral tendon from the
base (``FROM_BASE``, ``--from-base``) it does not.  The
measurements, the settings tried and why are in ``docs/movement.md``.
"""
from __future__ import annotations

import dataclasses
import pathlib
import time

import numpy as np
from dm_control.rl import control as control_lib

from robostrich_suite import cli as cli_lib
from robostrich_suite import outputs
from robostrich_suite import physics as physics_lib
from robostrich_suite.model import arm as arm_lib
from robostrich_suite import scenes
from robostrich_suite.studies import movement_figure
from robostrich_suite.tasks.conventions import CONTROL_TIMESTEP, PHYSICS_TIMESTEP
from robostrich_suite import rerun_blueprint, rerun_log

PATTERNS = ("rolling", "lever")
SETTLE_TIME = 3.0  # s before the ventral ramps start: the start pose comes to rest
RAMP_IN_TIME = 1.0  # s over which the start inputs are ramped in from the straight neck
HOLD_TIME = 1.5  # s after the last ramp, to see the end pose at rest
DORSAL_HOLD_GAIN = 30.0  # 1/s, integral gain of the dorsal length hold
# What PATTERN.rrd opens on, beside the arm (robostrich_suite.rerun_blueprint).
MOVEMENT_SERIES = (("Tendon inputs", ["tendon_input/**"]), ("Tendon contraction", ["tendon_contraction/**"]),
                   ("Head attitude (deg)", ["head/attitude_deg"]))
RECORD_EVERY = int(round(CONTROL_TIMESTEP / PHYSICS_TIMESTEP))  # physics steps per frame: a control step


@dataclasses.dataclass(frozen=True)
class MovementConfig:
    """Scripted inputs of one movement test (contractions in metres).

    The defaults are the setting in which the paper's difference shows (see
    docs/movement.md): ventral slips four joints long (the tasks' arm), the dorsal
    servo's input held, rolling as a travelling wave.  ``FROM_BASE`` is the same test
    on the ``ventral_from_base`` routing, whose ventral tendons all run from the base.
    """
    pattern: str = "rolling"
    dorsal: float = -0.02  # dorsal contraction held throughout (negative = paid out)
    amplitude: float = 0.05  # ventral contraction each tendon is ramped to
    ramp_time: float = 2.0  # s per tendon (rolling); the lever ramps all over the same total
    dorsal_hold: str = "input"  # "length": hold the tendon length; "input": hold the input
    release: bool = True  # rolling: release each tendon while the next one contracts
    ventral_span: int | None = 4  # ventral slips this many joints long; None: from the base
    lever_amplitude: float | None = None  # lever's ventral contraction (default: amplitude)

    def validate(self, num_ventral: int) -> None:
        if self.pattern not in PATTERNS:
            raise ValueError(f"unknown pattern {self.pattern!r}; use one of {PATTERNS}")
        if self.dorsal_hold not in ("length", "input"):
            raise ValueError(f"dorsal_hold must be 'length' or 'input', got {self.dorsal_hold!r}")
        if not self.ramp_time > 0:
            raise ValueError(f"ramp_time must be positive, got {self.ramp_time}")
        if num_ventral < 2:
            raise ValueError("a movement test needs at least two ventral tendons")

    def duration(self, num_ventral: int) -> float:
        return SETTLE_TIME + (num_ventral - 1) * self.ramp_time + HOLD_TIME

    def layout(self, spec: arm_lib.ArmSpec) -> arm_lib.TendonLayout:
        if self.ventral_span is None:
            return arm_lib.TendonLayout.ventral_from_base(spec)
        return arm_lib.TendonLayout.ventral_slips(spec, self.ventral_span)

    def ventral_amplitude(self) -> float:
        if self.pattern == "lever" and self.lever_amplitude is not None:
            return self.lever_amplitude
        return self.amplitude


# Every ventral tendon from the base (ventral_from_base), dorsal length held as in the
# paper, rolling as successive contractions: both patterns end in the same pose.
FROM_BASE = dict(ventral_span=None, dorsal_hold="length", release=False, ramp_time=1.0)


def hold_dorsal_length(dorsal_input: float, target: float, contraction: float, dt: float,
                       control_range) -> float:
    """One step of the integral loop that holds the dorsal tendon at ``target`` contraction
    by moving its input against the servo's own stretch."""
    return float(np.clip(dorsal_input + DORSAL_HOLD_GAIN * dt * (target - contraction),
                         *control_range))


def ventral_amplitudes(config: MovementConfig, physics: scenes.FramePhysics) -> np.ndarray:
    """The contraction (m) each ventral tendon is ramped to: the configured amplitude,
    clipped to that tendon's input range (so most get less than asked)."""
    low, high = physics.model.actuator_ctrlrange.T
    ventral = physics_lib.ventral_indices(physics.model)
    return np.clip(config.ventral_amplitude(), low[ventral], high[ventral])


def schedule(config: MovementConfig, physics: scenes.FramePhysics):
    """``f(t) -> contraction targets`` for every tendon (dorsal: the held contraction).

    Both patterns start from the same pose (dorsal at ``dorsal``, the most caudal
    ventral tendon at ``amplitude``) and ramp the others over the same total time.
    """
    ventral = physics_lib.ventral_indices(physics.model)
    dorsal = physics_lib.dorsal_index(physics.model)
    amplitude = ventral_amplitudes(config, physics)
    total = (len(ventral) - 1) * config.ramp_time

    def targets(t: float) -> np.ndarray:
        x = np.zeros(physics.model.nu)
        ramp_in = min(t / RAMP_IN_TIME, 1.0)
        x[dorsal] = ramp_in * config.dorsal
        x[ventral[0]] = ramp_in * amplitude[0]
        s = t - SETTLE_TIME
        if config.pattern == "rolling":
            for j in range(1, len(ventral)):
                a = np.clip((s - (j - 1) * config.ramp_time) / config.ramp_time, 0.0, 1.0)
                x[ventral[j]] = a * amplitude[j]
                if config.release:
                    x[ventral[j - 1]] = min(x[ventral[j - 1]], (1.0 - a) * amplitude[j - 1])
        else:
            a = np.clip(s / total, 0.0, 1.0)
            x[ventral[1:]] = a * amplitude[1:]
        return x

    return targets


@dataclasses.dataclass
class Movement:
    """What one movement test did, one row per recorded frame."""
    config: MovementConfig
    tendon_names: list[str]
    tendon_sides: list[str]  # physics.tendon_sides: "dorsal" or "ventral" per tendon
    time: np.ndarray  # (n,) s
    control: np.ndarray  # (n, nu) actuator inputs (m)
    contraction: np.ndarray  # (n, nu) measured tendon contractions (m)
    head_position: np.ndarray  # (n, 2) x, z (m)
    head_attitude: np.ndarray  # (n,) deg
    joint_points: np.ndarray  # (n, num_joints + 1, 2): base joint ... atlas joint, head tip
    ventral_amplitudes: np.ndarray  # (num_ventral,) m, each ventral tendon's peak input

    @property
    def settle_time(self) -> float:
        """Seconds before the ventral ramps start (the start pose coming to rest)."""
        return SETTLE_TIME

    @property
    def moving(self) -> np.ndarray:
        """Frames from the start of the ventral ramps on."""
        return self.time >= SETTLE_TIME

    def head_travel(self) -> float:
        """Distance (m) between the head's positions at the start and the end of the ramps."""
        path = self.head_position[self.moving]
        return float(np.linalg.norm(path[-1] - path[0]))

    def head_path_length(self) -> float:
        path = self.head_position[self.moving]
        return float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1)))

    def attitude_range(self) -> float:
        """Largest minus smallest head attitude (deg, unwrapped) while the ventral tendons move."""
        attitude = np.degrees(np.unwrap(np.radians(self.head_attitude[self.moving])))
        return float(np.ptp(attitude))

    def amplitude_text(self) -> str:
        """The ventral inputs' peaks as plotted, and what was asked when that was clipped."""
        low, high = 1000 * self.ventral_amplitudes.min(), 1000 * self.ventral_amplitudes.max()
        applied = f"{low:.1f} mm" if high - low < 0.05 else f"{low:.0f}-{high:.0f} mm"
        asked = 1000 * self.config.ventral_amplitude()
        if np.isclose(asked, 1000 * self.ventral_amplitudes).all():
            return applied
        return f"{applied} ({asked:.1f} mm asked, clipped to each tendon's range)"

    def summary(self) -> dict:
        return {"pattern": self.config.pattern, "head_travel_m": round(self.head_travel(), 4),
                "head_path_m": round(self.head_path_length(), 4),
                "attitude_range_deg": round(self.attitude_range(), 2),
                "attitude_start_deg": round(float(self.head_attitude[self.moving][0]), 2),
                "attitude_end_deg": round(float(self.head_attitude[-1]), 2)}


def _chain_points(physics: scenes.FramePhysics, spec: arm_lib.ArmSpec) -> np.ndarray:
    """Joint positions from the base (C18) joint to the atlas, then the head tip, as (x, z)."""
    names = [f"{arm_lib.ARM_MODEL_NAME}/{n}" for n in reversed(spec.joint_names)]
    points = [physics.named.data.xpos[n][[0, 2]] for n in names]
    head = physics.named.data.xpos[names[-1]]
    axis = physics_lib.head_axis(physics)
    points.append((head + spec.head_length * axis)[[0, 2]])
    return np.array(points)


def run(config: MovementConfig, spec: arm_lib.ArmSpec | None = None,
        physics: scenes.FramePhysics | None = None, recording=None, progress: bool = False
        ) -> Movement:
    """Simulate one movement test; log it to ``recording`` (a Rerun stream) if given."""
    spec = spec or arm_lib.ArmSpec.from_table1()
    physics = physics or scenes.frame_physics(spec, config.layout(spec))
    ventral = physics_lib.ventral_indices(physics.model)
    config.validate(len(ventral))
    dorsal = physics_lib.dorsal_index(physics.model)
    model = physics.model
    targets = schedule(config, physics)
    dt = model.opt.timestep
    steps = int(round(config.duration(len(ventral)) / dt))
    names = [model.id2name(i, "actuator").split("/")[-1] for i in range(model.nu)]
    sides = physics_lib.tendon_sides(model)

    if recording is not None:
        rerun_log.log_geometry(recording, physics)

    physics.reset()
    dorsal_input = 0.0
    rows = []
    iterator = range(steps + 1)
    if progress:
        from tqdm import tqdm
        iterator = tqdm(iterator, desc=config.pattern, unit="step", mininterval=1.0)
    for k in iterator:
        t = k * dt
        x = targets(t)
        contraction = physics.tendon_contractions()
        if config.dorsal_hold == "length":
            dorsal_input = hold_dorsal_length(dorsal_input, x[dorsal], contraction[dorsal], dt,
                                              model.actuator_ctrlrange[dorsal])
            x[dorsal] = dorsal_input
        physics.data.ctrl[:] = x
        if k % RECORD_EVERY == 0:
            head = physics.head_position()[[0, 2]]
            attitude = physics.head_attitude()
            rows.append((t, x.copy(), contraction, head, attitude, _chain_points(physics, spec)))
            if recording is not None:
                _log_frame(recording, physics, rows, names, sides)
        if k < steps:
            physics.step()
            if physics.divergence is not None:
                raise control_lib.PhysicsError(f"{config.pattern} test diverged at t = {t:.3f} s: "
                                               f"{physics.divergence}")
    time_, control, contraction, head, attitude, points = (np.array(c) for c in zip(*rows))
    return Movement(config, names, sides, time_, control, contraction, head, attitude, points,
                    ventral_amplitudes(config, physics))


def match_lever_amplitude(config: MovementConfig, travel: float,
                          spec: arm_lib.ArmSpec | None = None, iterations: int = 7,
                          progress: bool = False) -> float:
    """The lever amplitude (m) whose head travel equals ``travel`` (m), by bisection.

    "Comparable head travel" made exact: the lever's head travel grows with how far
    all its tendons are contracted, so halving the interval ``iterations`` times
    matches it to within ``amplitude / 2**iterations`` of contraction.  Returns
    ``config.amplitude`` when even that does not move the head as far.
    """
    spec = spec or arm_lib.ArmSpec.from_table1()
    lever = dataclasses.replace(config, pattern="lever")
    low, high = 0.0, config.amplitude
    if run(dataclasses.replace(lever, lever_amplitude=high), spec).head_travel() <= travel:
        return high
    steps = range(iterations)
    if progress:
        from tqdm import tqdm
        steps = tqdm(steps, desc="matching the lever's head travel", unit="run")
    for _ in steps:
        middle = 0.5 * (low + high)
        if run(dataclasses.replace(lever, lever_amplitude=middle), spec).head_travel() < travel:
            low = middle
        else:
            high = middle
    return 0.5 * (low + high)


def _log_frame(recording, physics, rows, names, sides) -> None:
    """One frame: body poses, tendon paths, inputs, attitude and the head path so far."""
    t, control, contraction, head, attitude, _ = rows[-1]
    rerun_log.set_sim_time(recording, t)
    rerun_log.log_body_poses(recording, physics)
    model, data = physics.model, physics.data
    for name, side, tendon in zip(names, sides, model.actuator_trnid[:, 0]):
        start, count = data.ten_wrapadr[tendon], data.ten_wrapnum[tendon]
        points = data.wrap_xpos[start:start + count]
        color = (220, 50, 50) if side == "dorsal" else (40, 110, 230)
        rerun_log.log_path(recording, f"world/tendons/{name}", points, color=color)
    rerun_log.log_scalars(recording, "tendon_input", dict(zip(names, control)))
    rerun_log.log_scalars(recording, "tendon_contraction", dict(zip(names, contraction)))
    rerun_log.log_scalars(recording, "head", {"attitude_deg": attitude})
    if len(rows) % 5 == 1:  # the path so far, every 0.04 s: a growing line is O(n^2) data
        path = [[r[3][0], 0.0, r[3][1]] for r in rows]
        rerun_log.log_path(recording, "world/head_path", path, color=(20, 20, 20))


# --------------------------------------------------------------------------- static poses

@dataclasses.dataclass
class PoseFamily:
    """Settled poses for random ventral inputs at one held dorsal length."""
    dorsal: float
    ventral_inputs: np.ndarray  # (n, num_ventral) m
    head_position: np.ndarray  # (n, 2) m
    head_attitude: np.ndarray  # (n,) deg
    settled: np.ndarray  # (n,) bool

    def attitude_spread(self, radius: float = 0.015) -> tuple[float, float]:
        """Median attitude difference (deg) of settled pose pairs whose heads are closer
        than ``radius`` m, and of pairs farther than 0.1 m apart.  A small first number
        means the attitude is a function of the head position: no ventral sequence can
        move the head along one path with two different attitude histories."""
        position = self.head_position[self.settled]
        attitude = self.head_attitude[self.settled]
        distance = np.linalg.norm(position[:, None] - position[None], axis=2)
        difference = np.abs(attitude[:, None] - attitude[None])
        near = (distance < radius) & (distance > 0)
        far = distance > 0.1
        median = lambda mask: float(np.median(difference[mask])) if mask.any() else float("nan")
        return median(near), median(far)


def pose_family(num_poses: int, dorsal: float = MovementConfig.dorsal, seed: int = 0,
                spec: arm_lib.ArmSpec | None = None, settle_time: float = 3.0,
                progress: bool = False, layout: arm_lib.TendonLayout | None = None
                ) -> PoseFamily:
    """Hold the dorsal length at ``dorsal`` and random ventral inputs; record where the head
    comes to rest.  Inputs are drawn as ``u**2`` times each tendon's range (more small
    contractions, where the head moves most), a third of them with four tendons slack."""
    spec = spec or arm_lib.ArmSpec.from_table1()
    physics = scenes.frame_physics(spec, layout)
    model = physics.model
    ventral, dorsal_id = physics_lib.ventral_indices(physics.model), physics_lib.dorsal_index(physics.model)
    high = model.actuator_ctrlrange[ventral, 1]
    rng = np.random.default_rng(seed)
    inputs = rng.uniform(size=(num_poses, len(ventral))) ** 2 * high
    for i in range(0, num_poses, 3):
        inputs[i, rng.choice(len(ventral), 4, replace=False)] = 0.0
    dt = model.opt.timestep
    positions, attitudes = np.zeros((num_poses, 2)), np.zeros(num_poses)
    settled = np.zeros(num_poses, bool)
    iterator = range(num_poses)
    if progress:
        from tqdm import tqdm
        iterator = tqdm(iterator, desc="static poses", unit="pose")
    for i in iterator:
        physics.reset()
        dorsal_input = 0.0
        for k in range(int(round(settle_time / dt))):
            ramp = min(k * dt / RAMP_IN_TIME, 1.0)
            contraction = physics.tendon_contractions()[dorsal_id]
            dorsal_input = hold_dorsal_length(dorsal_input, ramp * dorsal, contraction, dt,
                                              model.actuator_ctrlrange[dorsal_id])
            physics.data.ctrl[dorsal_id] = dorsal_input
            physics.data.ctrl[ventral] = ramp * inputs[i]
            physics.step()
        settled[i] = physics.divergence is None and np.abs(physics.data.qvel).max() < 0.05
        positions[i] = physics.head_position()[[0, 2]]
        attitudes[i] = physics.head_attitude()
    return PoseFamily(dorsal, inputs, positions, attitudes, settled)


# --------------------------------------------------------------------------- command line

MAX_RAMP_TIME = 60.0  # s per tendon: the whole test is about 8 of them


def build_parser() -> cli_lib.Parser:
    parser = cli_lib.Parser(
        prog="robostrich-movement",
        description="The paper's movement tests (Sec. 4.3, Figs. 4-5): rolling and lever "
                    "patterns of the ventral tendons while the dorsal tendon is held. Writes "
                    "{pattern}.png (tendon inputs, head attitude, stick figures) and "
                    "{pattern}.rrd (open with `rerun FILE`). The defaults show the paper's "
                    "difference; --from-base runs the same test on the routing with every "
                    "ventral tendon from the base, where it does not appear (see docs/movement.md).")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/movement"),
                        help="output directory (default: %(default)s)")
    parser.add_argument("--patterns", nargs="+", choices=PATTERNS, default=list(PATTERNS),
                        help="movement patterns to run (default: all)")
    parser.add_argument("--from-base", action="store_true",
                        help="the ventral_from_base routing (every ventral tendon from the base), dorsal length "
                             "held, successive contractions; overrides --ventral-span, "
                             "--dorsal-hold, --ramp-time and --no-release")
    defaults = MovementConfig()
    parser.add_argument("--ventral-span", type=cli_lib.whole_number(1, 17), default=defaults.ventral_span,
                        metavar="K", help="ventral slips tied K joints caudal of their "
                        "insertions (TendonLayout.ventral_slips) (default: %(default)s)")
    parser.add_argument("--dorsal", type=cli_lib.number(-0.5, 0.5, " m"), default=defaults.dorsal,
                        help="dorsal contraction held throughout, m; a contraction is the tendon's shortening "
                             "from its length at zero input: positive pulls, negative pays it out (default: %(default)s)")
    parser.add_argument("--amplitude", type=cli_lib.number(-0.5, 0.5, " m"), default=defaults.amplitude,
                        help="ventral contraction per tendon, m, signed as --dorsal (default: %(default)s)")
    parser.add_argument("--ramp-time", type=cli_lib.seconds(maximum=MAX_RAMP_TIME), default=defaults.ramp_time,
                        help="seconds per ventral tendon (default: %(default)s)")
    parser.add_argument("--dorsal-hold", choices=("length", "input"),
                        default=defaults.dorsal_hold,
                        help="hold the dorsal tendon's length or its input (default: %(default)s)")
    parser.add_argument("--no-release", action="store_true",
                        help="rolling: keep each tendon contracted instead of letting it go as "
                             "the next one contracts")
    parser.add_argument("--no-match-travel", action="store_true",
                        help="ramp the lever to --amplitude instead of bisecting its amplitude "
                             "until its head travel equals the rolling pattern's")
    parser.add_argument("--joint-stiffness", type=cli_lib.number(0, 1e4, " N m/rad"), default=None,
                        help="override the passive joint stiffness, N m/rad (default: the arm's)")
    parser.add_argument("--seed", type=cli_lib.seed, default=0,
                        help="seed of --pose-family's random inputs (default: %(default)s)")
    parser.add_argument("--pose-family", type=cli_lib.whole_number(0, 100_000), default=0, metavar="N",
                        help="also settle N random ventral inputs at the held dorsal length and "
                             "print how tightly the attitude follows the head position "
                             "(about 0.1 s each; default: %(default)s)")
    parser.add_argument("--no-rerun", "--no-recording", dest="no_recording", action="store_true", help="no .rrd recordings")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    return parser


def main(argv=None) -> dict:
    """Command line: run both patterns, write a PNG and a Rerun recording of each."""
    args = build_parser().parse_args(argv)
    outputs.check_directory(args.out)
    overrides = {} if args.joint_stiffness is None else {"joint_stiffness": args.joint_stiffness}
    spec = arm_lib.ArmSpec.from_table1(**overrides)
    setting = dict(ventral_span=args.ventral_span, dorsal=args.dorsal, amplitude=args.amplitude,
                   ramp_time=args.ramp_time, dorsal_hold=args.dorsal_hold,
                   release=not args.no_release)
    if args.from_base:
        setting.update(FROM_BASE)
    base = MovementConfig(**setting)
    ventral = sum(t.side == "ventral" for t in base.layout(spec).tendons)
    for pattern in args.patterns:  # every bad setting before anything is written
        dataclasses.replace(base, pattern=pattern).validate(ventral)
    start = time.perf_counter()
    results, written = run_patterns(args, base, spec)
    if args.pose_family > 0:
        family = pose_family(args.pose_family, base.dorsal, args.seed, spec, progress=not args.no_progress,
                             layout=base.layout(spec))
        near, far = family.attitude_spread()
        print(f"static poses at dorsal {base.dorsal} m: {family.settled.sum()} of "
              f"{args.pose_family} settled; attitude differs by a median {near:.1f} deg between "
              f"heads within 15 mm, {far:.1f} deg between heads over 100 mm apart")
    for path in written:
        print(f"wrote {path}")
    print(f"done in {time.perf_counter() - start:.1f} s")
    return results


def run_patterns(args, base: MovementConfig, spec) -> tuple[dict, list]:
    """Each pattern of ``args.patterns`` (rolling first: the lever matches its head travel), with
    its figure and recording; prints a line per pattern and the ratio. Returns (results, files)."""
    progress = not args.no_progress
    written, results = [], {}
    for pattern in sorted(args.patterns, key=PATTERNS.index):
        config = dataclasses.replace(base, pattern=pattern)
        if pattern == "lever" and "rolling" in results and not args.no_match_travel:
            amplitude = match_lever_amplitude(config, results["rolling"].head_travel(), spec,
                                              progress=progress)
            config = dataclasses.replace(config, lever_amplitude=amplitude)
        rrd = args.out / f"{pattern}.rrd"
        if args.no_recording:
            movement = run(config, spec, progress=progress)
        else:
            layout = rerun_blueprint.robot_and_series(MOVEMENT_SERIES, rerun_blueprint.SIDE_EYE)
            with rerun_log.recording(f"robostrich_movement_{pattern}", rrd, blueprint=layout) as recording:
                movement = run(config, spec, recording=recording, progress=progress)
            written.append(rrd)
        written.append(movement_figure.plot_movement(movement, args.out / f"{pattern}.png"))
        results[pattern] = movement
        s = movement.summary()
        print(f"{pattern:8s} head travel {1000 * s['head_travel_m']:6.1f} mm "
              f"(path {1000 * s['head_path_m']:.0f} mm), attitude "
              f"{s['attitude_start_deg']:.1f} -> {s['attitude_end_deg']:.1f} deg, "
              f"range {s['attitude_range_deg']:.1f} deg, ventral inputs up to "
              f"{movement.amplitude_text()}")
    if len(results) == 2:
        ratio = results["rolling"].attitude_range() / max(results["lever"].attitude_range(), 1e-9)
        print(f"attitude range rolling / lever: {ratio:.2f}")
        written.append(movement_figure.plot_comparison(results, args.out / "rolling_vs_lever.png"))
    return results, written


def cli(argv=None) -> int:
    """Console script `robostrich-movement`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-movement", argv)


if __name__ == "__main__":
    import sys
    sys.exit(cli())
