"""Where the head can go: the kinematic and the actuated workspace (paper Sec. 4.4, Fig. 6).

The *kinematic* workspace samples joint angles uniformly within Table 1's
limits and asks MuJoCo's forward kinematics where the head is: all samples are
the paper's red region, those with the head level (attitude 90 +- 5 deg) its
blue region.  The *actuated* workspace holds random tendon inputs until the
passive chain settles under gravity and records where the head came to rest:
poses the arm really reaches.  A chain hanging on its tendons under gravity
reaches less than the kinematic region, so the paper's blue region contains
targets the arm cannot hold.  The actuated level-head subset is therefore the
one source of the tasks' targets (see :mod:`robostrich_suite.targets`).

    robostrich-workspace --out out/workspace   # Fig. 6 + actuated overlay, samples .npz
"""
from __future__ import annotations

import dataclasses
import pathlib
import time

import mujoco
import numpy as np

from robostrich_suite import atomic_files
from robostrich_suite import cli as cli_lib
from robostrich_suite import outputs, parallel
from robostrich_suite import progress as progress_lib
from robostrich_suite import physics as physics_lib
from robostrich_suite.model import arm as arm_lib
from robostrich_suite import fingerprint as fingerprint_lib
from robostrich_suite import scenes
from robostrich_suite.studies import workspace_figure
from robostrich_suite.tasks.conventions import LEVEL_ATTITUDE_DEG, LEVEL_TOLERANCE_DEG
from robostrich_suite.tasks.lessons import LESSON_TIME_LIMIT

# s an input is held from reset before the pose counts: one lesson episode, the time the lookup
# baseline and a policy have (the slips' neck swings longer than 1.5 s after some inputs).
SETTLE_TIME = LESSON_TIME_LIMIT
# Joint limits are soft constraints (arm.ArmSpec.limit_solref): a settled pose may
# sit slightly past Table 1.  Measured over 1200 random tendon inputs: at most 0.8 deg.
LIMIT_TOLERANCE_DEG = 1.0
ACTUATED = "actuated workspace"  # the progress bar of the held-input draw


def base_joint_xz(physics: scenes.FramePhysics, spec: arm_lib.ArmSpec | None = None) -> np.ndarray:
    """World (x, z) of the joint between the base link (C18) and the frame (Fig. 6's black dot)."""
    spec = spec or arm_lib.ArmSpec.from_table1()
    return np.array(physics.named.data.xpos[f"{arm_lib.ARM_MODEL_NAME}/{spec.base_link}"])[[0, 2]]


def reach_radius(spec: arm_lib.ArmSpec | None = None) -> float:
    """Farthest the head site can be from the base joint: all links straight plus the head."""
    return arm_lib.reach(spec or arm_lib.ArmSpec.from_table1())


# --------------------------------------------------------------------------- kinematic

@dataclasses.dataclass
class KinematicSamples:
    """Head poses of joint angles drawn within the joint limits."""
    joint_angles: np.ndarray  # (n, num_joints) rad, Table 1 order (atlas first)
    head_position: np.ndarray  # (n, 2) x, z in metres
    head_attitude: np.ndarray  # (n,) degrees
    uniform: np.ndarray  # (n,) bool: drawn uniformly (the paper's way) or an edge sample

    def level(self, tolerance_deg: float = LEVEL_TOLERANCE_DEG) -> np.ndarray:
        """Mask of the paper's blue region: head attitude 90 +- tolerance deg."""
        return np.abs(physics_lib.attitude_error_deg(self.head_attitude, LEVEL_ATTITUDE_DEG)) <= tolerance_deg


EDGE_SPREAD = 0.1  # per-joint spread of an edge sample around its segment's limit fraction
EDGE_SEGMENTS = 3  # an edge sample bends up to this many stretches of the neck, each its own way


def sample_joint_angles(num_uniform: int, num_edge: int, rng: np.random.Generator,
                        spec: arm_lib.ArmSpec) -> np.ndarray:
    """Joint angles within the limits, Table 1 order.

    ``num_uniform`` are uniform in the box of limits (the paper's Fig. 6).  With 18
    joints a uniform draw almost never bends many neighbouring joints the same way,
    so the region's edges (neck curled far forward or back, or hanging forward as
    the actuated arm does) stay nearly empty.  An *edge* sample cuts the chain at
    random into ``EDGE_SEGMENTS`` stretches, draws for each stretch one fraction
    ``b ~ U(0, 1)`` of the way from the dorsal to the ventral limit and puts its
    joints near it (spread ``EDGE_SPREAD``).  Both kinds stay within the limits, so
    both are poses of the kinematic workspace.
    """
    limits = spec.joint_range_rad()
    low, width = limits[:, 0], limits[:, 1] - limits[:, 0]
    n = spec.num_joints
    uniform = rng.uniform(size=(num_uniform, n))
    cuts = np.sort(rng.integers(0, n + 1, size=(num_edge, EDGE_SEGMENTS - 1)), axis=1)
    segment = (np.arange(n)[None, :, None] >= cuts[:, None, :]).sum(axis=2)  # (num_edge, n)
    fractions = rng.uniform(size=(num_edge, EDGE_SEGMENTS))
    common = np.take_along_axis(fractions, segment, axis=1)
    edge = np.clip(common + EDGE_SPREAD * rng.standard_normal((num_edge, n)), 0, 1)
    angles = low + width * np.concatenate([uniform, edge])
    return np.clip(angles, limits[:, 0], limits[:, 1])  # no rounding past a limit


def kinematic_samples(num_samples: int, seed: int = 0, spec: arm_lib.ArmSpec | None = None,
                      physics: scenes.FramePhysics | None = None, progress: bool = False,
                      num_edge: int = 0) -> KinematicSamples:
    """``num_samples`` uniform joint angles within Table 1's limits (plus ``num_edge`` edge
    samples, see :func:`sample_joint_angles`); head pose by MuJoCo forward kinematics."""
    spec = spec or arm_lib.ArmSpec.from_table1()
    physics = physics or scenes.frame_physics(spec)
    angles = sample_joint_angles(num_samples, num_edge, np.random.default_rng(seed), spec)
    total = len(angles)
    model, data = physics.model.ptr, physics.data.ptr
    indices = physics_lib.arm_indices(physics.model)
    qpos_adr, site, head_body = indices.qpos, indices.head_site, indices.head_body
    positions = np.empty((total, 2))
    axes = np.empty((total, 2))
    with progress_lib.bar(progress, total=total, desc="kinematic workspace", unit="pose", mininterval=1.0) as bar:
        for i in range(total):
            data.qpos[qpos_adr] = angles[i]
            mujoco.mj_kinematics(model, data)
            positions[i] = data.site_xpos[site, [0, 2]]
            axes[i] = data.xmat[head_body, [2, 8]]  # head z axis: world x and z components
            if bar is not None:
                bar.update()
    attitudes = physics_lib.continuous_attitude_deg(np.degrees(np.arctan2(axes[:, 0], axes[:, 1])), angles)
    uniform = np.arange(total) < num_samples
    return KinematicSamples(angles, positions, attitudes, uniform)


# --------------------------------------------------------------------------- actuated

@dataclasses.dataclass
class ActuatedSamples:
    """Settled head poses under random constant tendon inputs."""
    head_position: np.ndarray  # (n, 2) x, z in metres
    head_attitude: np.ndarray  # (n,) degrees
    control: np.ndarray  # (n, num_tendons) the inputs that hold each pose
    settled: np.ndarray  # (n,) bool: joint speeds below the threshold at the end
    joint_angles: np.ndarray | None = None  # (n, num_joints) rad, Table 1 order

    def level(self, tolerance_deg: float = LEVEL_TOLERANCE_DEG) -> np.ndarray:
        """Mask of settled poses with the head level (90 +- tolerance deg)."""
        return self.settled & (np.abs(physics_lib.attitude_error_deg(self.head_attitude, LEVEL_ATTITUDE_DEG))
                                <= tolerance_deg)

    @classmethod
    def concatenate(cls, parts) -> "ActuatedSamples":
        fields = [f.name for f in dataclasses.fields(cls)]
        return cls(*(None if any(getattr(p, f) is None for p in parts)
                     else np.concatenate([getattr(p, f) for p in parts]) for f in fields))


def settle(physics: scenes.FramePhysics, control: np.ndarray, settle_time: float = SETTLE_TIME,
           speed_tolerance: float = 0.05) -> bool:
    """Reset, hold ``control`` for ``settle_time`` seconds; True if the arm came to rest.
    A simulation that diverged never did, even where MuJoCo's reset left it still."""
    physics.reset()
    physics.data.ctrl[:] = control
    steps = int(round(settle_time / physics.model.opt.timestep))
    physics.step(steps)
    return bool(physics.divergence is None and np.abs(physics.data.qvel).max() < speed_tolerance)


LEVEL_SEEK_GAIN = 1e-3  # m of dorsal input per degree of attitude error per second


def seek_level(physics: scenes.FramePhysics, control: np.ndarray, seek_time: float) -> np.ndarray:
    """From reset, hold ``control`` but servo the dorsal input (:func:`physics_lib.dorsal_index`) on
    the head attitude towards 90 deg for ``seek_time`` seconds; return the inputs with the
    final dorsal input.

    The result is only a candidate: :func:`settle` then holds it constant from reset, and
    only a pose that comes to rest level there counts."""
    control = np.array(control, dtype=float)
    dorsal = physics_lib.dorsal_index(physics.model)
    low, high = physics.model.actuator_ctrlrange[dorsal]
    dt = physics.model.opt.timestep
    physics.reset()
    physics.data.ctrl[:] = control
    for _ in range(int(round(seek_time / dt))):
        error = float(physics_lib.attitude_error_deg(physics.head_attitude(), LEVEL_ATTITUDE_DEG))
        control[dorsal] = np.clip(control[dorsal] + LEVEL_SEEK_GAIN * error * dt, low, high)
        physics.data.ctrl[dorsal] = control[dorsal]
        physics.step()
    return control


def actuated_samples(num_samples: int, seed: int = 0, settle_time: float = SETTLE_TIME,
                     physics: scenes.FramePhysics | None = None, progress: bool = False,
                     seek_level_time: float = 0.0, spec: arm_lib.ArmSpec | None = None,
                     layout: arm_lib.TendonLayout | None = None) -> ActuatedSamples:
    """Hold uniformly random tendon inputs and record the settled head poses.

    With ``seek_level_time > 0`` the dorsal input of each draw is first tuned for a level
    head (:func:`seek_level`) and the tuned inputs are held: many times more level poses
    for a few times the simulation.
    """
    spec = spec or arm_lib.ArmSpec.from_table1()
    physics = physics or scenes.frame_physics(spec, layout)
    rng = np.random.default_rng(seed)
    low, high = physics.model.actuator_ctrlrange.T
    controls = rng.uniform(low, high, size=(num_samples, physics.model.nu))
    positions = np.zeros((num_samples, 2))
    attitudes = np.zeros(num_samples)
    settled = np.zeros(num_samples, bool)
    angles = np.zeros((num_samples, spec.num_joints))
    with progress_lib.bar(progress, total=num_samples, desc=ACTUATED, unit="pose") as bar:
        for i in range(num_samples):
            if seek_level_time > 0:
                controls[i] = seek_level(physics, controls[i], seek_level_time)
            settled[i] = settle(physics, controls[i], settle_time)
            positions[i] = physics.head_position()[[0, 2]]
            attitudes[i] = physics.head_attitude()
            angles[i] = physics.joint_angles()
            parallel.count()  # the parent's bar, in a worker of actuated_samples_parallel
            if bar is not None:
                bar.update()
    return ActuatedSamples(positions, attitudes, controls, settled, angles)


def _actuated_chunk(args) -> ActuatedSamples:
    num, seed, settle_time, seek_level_time, spec, layout = args
    return actuated_samples(num, seed=seed, settle_time=settle_time, seek_level_time=seek_level_time,
                            spec=spec, layout=layout)


def actuated_samples_parallel(num_samples: int, seed: int = 0, settle_time: float = SETTLE_TIME,
                              workers: int = 2, progress: bool = False,
                              seek_level_time: float = 0.0,
                              spec: arm_lib.ArmSpec | None = None,
                              layout: arm_lib.TendonLayout | None = None) -> ActuatedSamples:
    """:func:`actuated_samples` split over processes (chunk ``i`` uses seed ``seed + i``), with
    one progress bar over all of them (robostrich_suite/parallel.py)."""
    if workers <= 1:
        return actuated_samples(num_samples, seed, settle_time, progress=progress,
                                seek_level_time=seek_level_time, spec=spec, layout=layout)
    chunk = -(-num_samples // workers)
    sizes = [min(chunk, num_samples - i * chunk) for i in range(workers)]
    jobs = [(size, seed + i, settle_time, seek_level_time, spec, layout)
            for i, size in enumerate(sizes) if size > 0]
    with progress_lib.bar(progress, total=num_samples, desc=ACTUATED, unit="pose") as bar:
        return ActuatedSamples.concatenate(parallel.map_processes(_actuated_chunk, jobs, bar))


# --------------------------------------------------------------------------- figure, files

def save_samples(path: str | pathlib.Path, kinematic: KinematicSamples,
                 actuated: ActuatedSamples | None, base_xz: np.ndarray) -> pathlib.Path:
    """Both sample sets in one ``.npz`` (``kinematic_*``, ``actuated_*``, masks included)."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    arrays = {f"kinematic_{f.name}": getattr(kinematic, f.name)
              for f in dataclasses.fields(kinematic)}
    arrays["kinematic_level"] = kinematic.level()
    if actuated is not None:
        arrays.update({f"actuated_{f.name}": getattr(actuated, f.name)
                       for f in dataclasses.fields(actuated) if getattr(actuated, f.name) is not None})
        arrays["actuated_level"] = actuated.level()
    if path.suffix != ".npz":  # where np.savez would have put it
        path = path.with_name(path.name + ".npz")
    with atomic_files.replaced_atomically(path) as handle:
        np.savez_compressed(handle, base_joint_xz=base_xz, reach_radius=reach_radius(),
                            fingerprint=np.array(fingerprint_lib.model_fingerprint()), **arrays)
    return path


def build_parser() -> cli_lib.Parser:
    """robostrich-workspace's flags."""
    parser = cli_lib.Parser(
        prog="robostrich-workspace",
        description="Kinematic workspace of the Robostrich arm (paper Fig. 6: red = all head "
                    f"positions, blue = head level {LEVEL_ATTITUDE_DEG:g}+-{LEVEL_TOLERANCE_DEG:g} "
                    "deg) and the actuated workspace (head "
                    "poses the tendons hold at rest under gravity). Writes workspace.png and "
                    "workspace_samples.npz.")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/workspace"),
                        help="output directory (default: %(default)s)")
    parser.add_argument("--seed", type=cli_lib.seed, default=0, help="random seed (default: %(default)s)")
    parser.add_argument("--samples", type=cli_lib.whole_number(0), default=200_000,
                        help="kinematic samples: uniform joint angles (default: %(default)s)")
    parser.add_argument("--edge-samples", type=cli_lib.whole_number(0), default=100_000,
                        help="extra kinematic samples with every joint near a common fraction of "
                             "its range, to fill the region's edges (default: %(default)s)")
    parser.add_argument("--actuated-samples", type=cli_lib.whole_number(0), default=600,
                        help="actuated samples: random held tendon inputs, 0 to skip "
                             "(default: %(default)s)")
    parser.add_argument("--settle-time", type=cli_lib.seconds(), default=SETTLE_TIME,
                        help="seconds each tendon input is held before the pose is recorded "
                             "(default: %(default)s)")
    parser.add_argument("--seek-level", type=cli_lib.seconds(allow_zero=True), default=0.0, metavar="SECONDS",
                        help="tune each draw's dorsal input for a level head for this long "
                             "before holding it (about 12 times more level poses for 2.7 "
                             "times the time; default: %(default)s = off)")
    parser.add_argument("--workers", type=cli_lib.whole_number(1, cli_lib.MAX_WORKERS), default=2,
                        help="processes for the actuated sampling (default: %(default)s)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    return parser


def main(argv=None) -> dict:
    """Command line: sample both workspaces, write the figure and the samples."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.samples + args.edge_samples == 0:
        parser.error("argument --samples: --samples and --edge-samples are both 0: no kinematic workspace to draw")
    outputs.check_directory(args.out)

    start = time.perf_counter()
    physics = scenes.frame_physics()
    kinematic = kinematic_samples(args.samples, args.seed, physics=physics,
                                  progress=not args.no_progress, num_edge=args.edge_samples)
    actuated = None
    if args.actuated_samples > 0:
        actuated = actuated_samples_parallel(args.actuated_samples, args.seed + 1,
                                             args.settle_time, args.workers,
                                             progress=not args.no_progress,
                                             seek_level_time=args.seek_level)
    base = base_joint_xz(physics)
    figure = workspace_figure.plot_workspace(kinematic, actuated, base, args.out / "workspace.png")
    samples = save_samples(args.out / "workspace_samples.npz", kinematic, actuated, base)
    level = kinematic.level()
    print(f"kinematic: {len(level)} samples ({kinematic.uniform.sum()} uniform), "
          f"{level.sum()} with the head level ({(level & kinematic.uniform).sum()} uniform) "
          f"({LEVEL_ATTITUDE_DEG:g}+-{LEVEL_TOLERANCE_DEG:g} deg); x {np.ptp(kinematic.head_position[:, 0]):.3f} m by "
          f"z {np.ptp(kinematic.head_position[:, 1]):.3f} m")
    if actuated is not None:
        print(f"actuated: {actuated.settled.sum()} of {len(actuated.settled)} settled, "
              f"{actuated.level().sum()} with the head level")
    print(f"wrote {figure}")
    print(f"wrote {samples}")
    print(f"done in {time.perf_counter() - start:.1f} s")
    return {"figure": figure, "samples": samples}


def cli(argv=None) -> int:
    """Console script `robostrich-workspace`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-workspace", argv)


if __name__ == "__main__":
    import sys
    sys.exit(cli())
