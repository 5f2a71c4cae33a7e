"""Ctrl-C and SIGTERM as a user or a batch scheduler sends them, at moments the commands mark in
their own output (never after a fixed sleep): every stop ends with the command's one line
(`robostrich-X: interrupted`, 130; `terminated`, 143) and nothing else on the screen, or, once the
command is done, with its success; never by the signal itself.

Commands run as installed scripts (conftest.console_script), their output read as it comes.
"""
import os
import pathlib
import signal
import subprocess
import sys
import threading
import time

import pytest

import conftest
from agents import checkpoint



class Running:
    """An installed command whose stdout and stderr are read as they come (threads), so the test
    can wait for a line, a progress bar or a file before it sends a signal."""

    def __init__(self, name, *args, new_session=False):
        self.name = name
        self.process = subprocess.Popen([conftest.console_script(name), *map(str, args)], stdout=subprocess.PIPE,
                                        stderr=subprocess.PIPE, env=conftest.COMMAND_ENVIRONMENT,
                                        start_new_session=new_session)
        self.out, self.err = bytearray(), bytearray()
        self.readers = [threading.Thread(target=self._read, args=(stream, into), daemon=True)
                        for stream, into in ((self.process.stdout, self.out), (self.process.stderr, self.err))]
        for reader in self.readers:
            reader.start()

    @staticmethod
    def _read(stream, into: bytearray):
        for chunk in iter(lambda: stream.read1(65536), b""):
            into.extend(chunk)

    def wait_for(self, condition, what: str, timeout: float = 400):
        deadline = time.monotonic() + timeout
        while not condition():
            assert self.process.poll() is None, f"{self.name} ended ({self.process.returncode}) before {what}: " \
                                                f"{self.stderr[-3000:]}"
            assert time.monotonic() < deadline, f"timed out waiting for {what}"
            time.sleep(0.05)

    def wait_for_output(self, text: str, stream: str = "stdout", timeout: float = 400):
        self.wait_for(lambda: text in getattr(self, stream), f"{text!r} on {stream}", timeout)

    def finish(self, timeout: float = 600) -> int:
        try:
            self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            raise
        for reader in self.readers:
            reader.join(10)
        return self.process.returncode

    @property
    def stdout(self) -> str:
        return self.out.decode(errors="replace")

    @property
    def stderr(self) -> str:
        return self.err.decode(errors="replace")

    def shown_lines(self) -> list:
        """stderr as a terminal shows it: each line's text after its last carriage return (where a
        progress bar redraws itself), blank ones left out."""
        return [shown for shown in (line.rsplit("\r", 1)[-1].rstrip() for line in self.stderr.split("\n")) if shown]


def assert_stopped(command: Running, status: int, word: str):
    returncode = command.finish()
    assert returncode == status, (returncode, command.stderr[-3000:])
    assert command.shown_lines() == [f"{command.name}: {word}"], command.stderr[-3000:]


TRAIN = ["--plan", "lesson1:2900,lesson2:2900", "--hidden-sizes", "16,16", "--batch-size", "16",
         "--min-replay-size", "50", "--num-eval-targets", "1", "--final-eval-targets", "1", "--eval-every", "5800",
         "--track-task", "", "--quiet", "--no-rerun", "--no-figures"]


def test_training_with_two_workers_names_the_checkpoints_they_wrote(tmp_path):
    """The parent's one line says where each worker's checkpoint went, as a run trained in one
    process says where its went. Stopped by SIGTERM (Ctrl-C: tests/test_hostile_input.py) once both
    runs are mid-training (each has an episode recorded) and with 5,800 steps to go, so both always
    write one."""
    out = tmp_path / "run"
    command = Running("robostrich-train", *TRAIN, "--out", out)
    metrics = [out / label / "metrics.jsonl" for label in ("curriculum", "baseline")]
    command.wait_for(lambda: all(p.exists() and p.stat().st_size > 0 for p in metrics), "an episode of each run")
    command.process.send_signal(signal.SIGTERM)
    returncode = command.finish()
    assert returncode == 143, command.stderr[-3000:]
    lines = command.stderr.strip().splitlines()
    assert lines[-1].startswith("robostrich-train: terminated (checkpoint written at step "), command.stderr[-3000:]
    for label in ("curriculum", "baseline"):
        path = out / label / "checkpoint.ckpt"
        steps = checkpoint._read_record(str(path))["payload"]["loop"]["env_steps"]
        assert f"at step {steps}: {path}" in lines[-1], (steps, lines[-1])
    assert "Traceback" not in command.stderr


def test_play_ends_with_its_line_wherever_it_is_stopped_and_succeeds_once_done(tmp_path):
    """Stopped while it evaluates the held-out targets (all of them: many seconds), while it runs
    track, and from the moment it has written everything until it exits (the interpreter takes a
    fraction of a second to shut down JAX and Rerun, with Python's default handlers back: a stop
    there ended the process by the signal, with no line)."""
    policy_line = "control steps of training)"
    marks = {"heldout": (policy_line, []), "track": ("heldout ", ["--num-targets", "1"]),
             "done": ("wrote ", ["--num-targets", "1"])}
    for phase, (mark, args) in marks.items():
        out = tmp_path / phase
        command = Running("robostrich-play", "--out", out, *args)
        command.wait_for_output(mark)
        command.process.send_signal(signal.SIGINT)
        if phase == "done":
            while command.process.poll() is None:  # Ctrl-C pressed again and again as it shuts down
                command.process.send_signal(signal.SIGINT)
                time.sleep(0.02)
            returncode = command.finish()
            assert returncode in (0, 130), (returncode, command.stderr[-3000:])  # never by the signal (-2)
            if returncode == 0:
                assert command.stderr == "", command.stderr[-3000:]
            else:
                assert command.shown_lines() == ["robostrich-play: interrupted"], command.stderr[-3000:]
            assert sorted(p.name for p in out.iterdir()) == ["robostrich_heldout.json", "robostrich_track.json",
                                                             "robostrich_track.png", "robostrich_track.rrd"]
        else:
            assert_stopped(command, 130, "interrupted")
            assert not list(out.glob("*.json")) and not list(out.glob(".*")), sorted(out.iterdir())


@pytest.mark.parametrize("workers, whole_group", [(2, False), (2, True), (1, False)],
                         ids=["to_the_command", "to_its_workers_too", "one_process"])
def test_targets_clears_its_progress_bar_before_its_line_and_stops_at_once(tmp_path, workers, whole_group):
    """Ctrl-C to the command alone or, as a terminal sends it, to its workers too: the bar is
    cleared, the one line stands alone, the workers stop at once (a million draws would take
    hours), none outlives the command, and no target file is written. The signal comes as soon as
    the bar is drawn, while the workers may still be starting."""
    out = tmp_path / "t.npz"
    command = Running("robostrich-targets", "--samples", "1000000", "--workers", workers, "--out", out,
                      new_session=True)
    command.wait_for(lambda: "pose/s]" in command.stderr, "the progress bar")
    if whole_group:
        os.killpg(command.process.pid, signal.SIGINT)
    else:
        command.process.send_signal(signal.SIGINT)
    started = time.monotonic()
    try:
        assert_stopped(command, 130, "interrupted")
        assert time.monotonic() - started < 60
        with pytest.raises(ProcessLookupError):  # no worker left in the command's process group
            os.killpg(command.process.pid, 0)
    finally:
        try:
            os.killpg(command.process.pid, signal.SIGKILL)  # whatever a failure left behind
        except ProcessLookupError:
            pass
    assert not any(pathlib.Path(tmp_path).iterdir())


def test_a_command_stopped_mid_recording_leaves_no_recording(tmp_path):
    """Stopped while they record a rollout (kept in memory until it is whole, robostrich_suite/rerun_log.py),
    stabilize and walk leave no .rrd, no partial file and no report. The recorded rollouts last 300 s
    of simulation, so the stop always lands in them; walk's bar is drawn once its recording is open."""
    commands = {"stabilize": Running("robostrich-stabilize", "--seeds", "200", "--time-limit", "300",
                                     "--no-figures", "--out", tmp_path / "stabilize"),
                "walk": Running("robostrich-walk", "--seconds", "300", "--out", tmp_path / "walk")}
    commands["stabilize"].wait_for_output("head_stabilize:", "stderr")
    commands["walk"].wait_for_output("walk:", "stderr")
    for name, command in commands.items():
        command.process.send_signal(signal.SIGINT)
        assert_stopped(command, 130, "interrupted")
        out = tmp_path / name
        assert not out.exists() or os.listdir(out) == [], os.listdir(out)


ACTED_ON = """
print("interrupted", cli.interrupted())
try:
    cli.raise_if_interrupted()
except KeyboardInterrupt:
    print("acted on")
"""
# Python runs both from wherever the program happens to be, and prints what they raise as ignored.
STOP_WHERE_EXCEPTIONS_ARE_IGNORED = {
    "gc callback": """
import gc, signal
from robostrich_suite import cli
cli._install(cli._on_sigint)
def callback(phase, info):  # as JAX's
    if phase == "start":
        signal.raise_signal(signal.SIGINT)
gc.callbacks.append(callback)
gc.collect()
gc.callbacks.remove(callback)
""" + ACTED_ON,
    "finaliser": """
import signal
from robostrich_suite import cli
cli._install(cli._on_sigint)
class Stream:  # as Rerun's RecordingStream, which flushes when its last reference goes
    def __del__(self):
        signal.raise_signal(signal.SIGINT)
Stream()
""" + ACTED_ON}


@pytest.mark.parametrize("where", sorted(STOP_WHERE_EXCEPTIONS_ARE_IGNORED))
def test_ctrl_c_where_python_ignores_exceptions_is_kept_for_the_loop_not_printed_as_ignored(where):
    """Ctrl-C landing in a gc callback (JAX registers one) or in an object's finaliser (Rerun's
    recording stream has one) only sets the flag: raised there, Python would print 'Exception
    ignored in ...' above the command's one line."""
    result = subprocess.run([sys.executable, "-c", STOP_WHERE_EXCEPTIONS_ARE_IGNORED[where]], capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0, result.stderr[-3000:]
    assert result.stdout.split("\n")[:2] == ["interrupted True", "acted on"], result.stdout
    assert "Exception ignored" not in result.stderr, result.stderr[-3000:]


STOP_AS_RERUN_OPENS_ITS_SINK = """
import signal, sys
from rerun import recording_stream
from robostrich_suite import cli, rerun_log
made = recording_stream.BinaryStream.__init__
def made_as_ctrl_c_lands(self, storage):  # Ctrl-C during Rerun's call is acted on as its wrapper runs
    signal.raise_signal(signal.SIGINT)
    made(self, storage)
recording_stream.BinaryStream.__init__ = made_as_ctrl_c_lands
cli._install(cli._on_sigint)
try:
    with rerun_log.recording("test", sys.argv[1]) as rec:
        print("block entered")
except KeyboardInterrupt:
    print("interrupted")
"""


def test_ctrl_c_while_rerun_opens_its_sink_drops_it_with_no_warning(tmp_path):
    """Rerun's in-memory sink holds the stream's opening messages as soon as its call returns: a
    KeyboardInterrupt raised there once dropped it unread, and Rerun printed its warning about
    dropped data above `robostrich-play: interrupted`. The stop is now acted on once the recording
    owns the sink, which it then drops: no block, no file, nothing on stderr."""
    path = tmp_path / "r.rrd"
    result = subprocess.run([sys.executable, "-c", STOP_AS_RERUN_OPENS_ITS_SINK, str(path)], capture_output=True,
                            text=True, timeout=120, env=conftest.COMMAND_ENVIRONMENT)
    assert result.returncode == 0, result.stderr[-3000:]
    assert result.stdout == "interrupted\n", result.stdout
    assert result.stderr == "", result.stderr[-3000:]
    assert not path.exists()
