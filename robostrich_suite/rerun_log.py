"""Drawing a MuJoCo model in Rerun: shapes once, body poses per step.

Every body becomes an entity ``{root}/bodies/{body}`` whose ``Transform3D``
is logged each step; its geoms are static children in the body frame
(capsules, boxes, spheres, cylinders as capsules, planes as thin boxes).  One
piece of code serves the arm on its frame and the arm on the quadruped.

    with rerun_log.recording("robostrich", "out/rollout.rrd") as rec:
        rerun_log.log_geometry(rec, physics)
        for t in ...:
            rerun_log.set_sim_time(rec, physics.data.time)
            rerun_log.log_body_poses(rec, physics)

A recording is kept in memory and written through the atomic writer once it is whole
(``RecordingFile``): an error or Ctrl-C mid-rollout leaves no half-written ``.rrd``, and a write
that fails (a full disk) is one OSError naming the file, not Rerun's log lines from its writer thread.

Time is on the ``sim_time`` timeline (seconds).  Rerun quaternions are xyzw;
MuJoCo's are wxyz.
"""
from __future__ import annotations

import pathlib
import re

import mujoco
import numpy as np
import rerun as rr

from robostrich_suite import atomic_files, cli

SIM_TIME = "sim_time"
DISCARD_FLUSH_SECONDS = 5.0  # a stopped command waits at most this for Rerun's batcher


class RecordingFile:
    """A recording stream encoded in memory, for a ``with`` block that gets the stream: the block's
    end writes it to ``path`` whole (through atomic_files.replaced_atomically, so a failed write
    names ``path`` and leaves no partial file), an error or Ctrl-C drops it (``path`` keeps what it
    held). Rerun's own file sink writes from a thread of its own and only logs a failed write; its
    stream read once, at the end, is the whole .rrd (one read per chunk would make a file of many
    streams, which Rerun calls corrupt). Memory: the recording's size, a few MB for a minute of the
    arm. ``blueprint`` (robostrich_suite.rerun_blueprint) goes into the file, so that a viewer opens
    it in that layout; ``send_blueprint`` can add it later.

    Rerun's objects exist only between ``open`` and ``close``/``discard``, each made and taken apart
    with Ctrl-C held off (cli.held_interrupts): Rerun's sink already holds the stream's opening
    messages when its call returns, and a KeyboardInterrupt raised there would drop it where nothing
    reads it, with Rerun's warning about dropped data above the command's one line."""

    def __init__(self, app_id: str, path: str | pathlib.Path, recording_id: str | None = None,
                 blueprint=None):
        self.path = pathlib.Path(path)
        self._identity = (app_id, recording_id)
        self._blueprint = blueprint
        self.stream: rr.RecordingStream | None = None
        self.encoded = None

    def open(self) -> rr.RecordingStream:
        """Make the stream and its in-memory sink; a stop that came meanwhile drops both and is raised."""
        try:
            with cli.held_interrupts():
                app_id, recording_id = self._identity
                self.stream = rr.RecordingStream(app_id, recording_id=recording_id)
                self.encoded = self.stream.binary_stream()
                if self._blueprint is not None:
                    self.send_blueprint(self._blueprint)
        except BaseException:
            self.discard()
            raise
        return self.stream

    def send_blueprint(self, blueprint) -> None:
        """Make ``blueprint`` the recording's active and default layout."""
        self.stream.send_blueprint(blueprint, make_active=True, make_default=True)

    def close(self) -> pathlib.Path:
        with cli.held_interrupts():
            data = self.encoded.read(flush=True) or b""
            self._disconnect()
        with atomic_files.replaced_atomically(self.path) as handle:
            handle.write(data)
        return self.path

    def discard(self) -> None:
        # Everything logged is taken first, as close() does, then whatever the disconnect still
        # pushes out: data left in the sink when it is dropped makes Rerun warn on stderr.
        with cli.deferred_interrupts():  # the stop (or error) that brought us here goes on after it
            if self.encoded is not None:
                self.encoded.read(flush=True, flush_timeout_sec=DISCARD_FLUSH_SECONDS)
            self._disconnect()

    def _disconnect(self) -> None:
        if self.stream is not None:
            self.stream.disconnect()
        if self.encoded is not None:
            self.encoded.read(flush=False)
        self.stream = self.encoded = None

    def __enter__(self) -> rr.RecordingStream:
        return self.open()

    def __exit__(self, error_type, error, traceback) -> None:
        """The recording is written if the block ran to its end, dropped otherwise."""
        self.close() if error_type is None else self.discard()


def recording(app_id: str, path: str | pathlib.Path, recording_id: str | None = None,
              blueprint=None) -> RecordingFile:
    """A recording stream for a ``with`` block, written to ``path`` (an ``.rrd`` file) with
    ``blueprint`` when the block ends without an error, and to no file otherwise (``RecordingFile``)."""
    return RecordingFile(app_id, path, recording_id, blueprint)


def set_sim_time(rec: rr.RecordingStream, seconds: float) -> None:
    rec.set_time(SIM_TIME, duration=float(seconds))


def _xyzw(wxyz) -> np.ndarray:
    wxyz = np.asarray(wxyz, dtype=np.float64)
    return np.array([wxyz[1], wxyz[2], wxyz[3], wxyz[0]])


def _entity(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_\-]", "_", name) or "unnamed"


def body_entity(physics, body_id: int, root: str = "world") -> str:
    name = physics.model.id2name(body_id, "body") or f"body_{body_id}"
    return f"{root}/bodies/{_entity(name)}"


def _rgba(rgba) -> list[int]:
    return [int(round(255 * float(np.clip(c, 0, 1)))) for c in rgba]


def log_geometry(rec: rr.RecordingStream, physics, root: str = "world",
                 skip_planes: bool = False) -> None:
    """Log every visible geom as a static shape in its body's frame."""
    model = physics.model
    types = mujoco.mjtGeom
    for geom_id in range(model.ngeom):
        rgba = model.geom_rgba[geom_id]
        if rgba[3] == 0:
            continue
        body = body_entity(physics, int(model.geom_bodyid[geom_id]), root)
        name = _entity(model.id2name(geom_id, "geom") or f"geom_{geom_id}")
        size = model.geom_size[geom_id]
        pos = model.geom_pos[geom_id]
        quat = model.geom_quat[geom_id]
        geom_type = int(model.geom_type[geom_id])  # a numpy int is never `in` a tuple of mjtGeom members
        color = [_rgba(rgba)]
        if geom_type in (types.mjGEOM_CAPSULE, types.mjGEOM_CYLINDER):
            rotation = np.zeros(9)
            mujoco.mju_quat2Mat(rotation, quat)
            start = pos - rotation.reshape(3, 3) @ np.array([0, 0, size[1]])
            shape = rr.Capsules3D(lengths=[2 * size[1]], radii=[size[0]], translations=[start],
                                  quaternions=[_xyzw(quat)], colors=color)
        elif geom_type == types.mjGEOM_BOX:
            shape = rr.Boxes3D(half_sizes=[size], centers=[pos], quaternions=[_xyzw(quat)],
                               colors=color)
        elif geom_type == types.mjGEOM_SPHERE:
            shape = rr.Ellipsoids3D(half_sizes=[[size[0]] * 3], centers=[pos], colors=color)
        elif geom_type == types.mjGEOM_ELLIPSOID:
            shape = rr.Ellipsoids3D(half_sizes=[size], centers=[pos], quaternions=[_xyzw(quat)],
                                    colors=color)
        elif geom_type == types.mjGEOM_PLANE and not skip_planes:
            half = [size[0] or 2.0, size[1] or 2.0, 0.001]
            shape = rr.Boxes3D(half_sizes=[half], centers=[pos], quaternions=[_xyzw(quat)],
                               colors=[[90, 100, 110, 255]], fill_mode="solid")
        else:
            continue
        rec.log(f"{body}/{name}", shape, static=True)


def log_body_poses(rec: rr.RecordingStream, physics, root: str = "world") -> None:
    """Log the world pose of every body (at the current time)."""
    data, model = physics.data, physics.model
    for body_id in range(1, model.nbody):
        rec.log(body_entity(physics, body_id, root),
                rr.Transform3D(translation=data.xpos[body_id],
                               quaternion=_xyzw(data.xquat[body_id])))


def log_scalars(rec: rr.RecordingStream, prefix: str, values: dict) -> None:
    """Log each ``name: value`` as a scalar series under ``prefix/name``."""
    for name, value in values.items():
        rec.log(f"{prefix}/{_entity(name)}", rr.Scalars(np.atleast_1d(np.asarray(value, float))))


def log_path(rec: rr.RecordingStream, entity: str, points, color=(255, 60, 60)) -> None:
    """A polyline, e.g. the head's path so far."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(points) >= 2:
        rec.log(entity, rr.LineStrips3D([points], colors=[color]))
