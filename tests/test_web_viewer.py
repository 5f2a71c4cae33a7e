"""`robostrich-play --web` as a user meets it: a real headless Chromium opens the page it serves, the
viewer loads the recording (the arm, the target, the head's path) in the layout the file carries,
and a screenshot lands in the test's output; a busy port is one line and exit 2; Ctrl-C ends the
server with exit 130.

The browser is the system's Chromium (Debian's `chromium`, which .ci/run installs) driven by
Playwright; the page is Rerun's WebGL/wasm viewer, drawn by Chromium's software rasterizer. What
the viewer holds is asked of the viewer itself (its `save_recording` / `save_blueprint`, the bytes
of the recording and layout it loaded) and read back with rerun-sdk, not guessed from pixels.
"""
import base64
import os
import pathlib
import re
import signal
import socket
import subprocess
import time

import pytest

import conftest
from robostrich_suite import rerun_blueprint

CHROMIUM = pathlib.Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
ARM = {"/world/bodies/arm_atlas/arm_atlas_geom", "/world/bodies/arm_c18/arm_c18_geom", "/world/target",
       "/world/head_path", "/plots/position_error_m"}
# The viewer's bytes as base64 (a Uint8Array of a megabyte does not cross to Python as JSON well).
SAVED = """() => {
  const handle = window._handle;
  if (!handle) return null;
  const encode = (bytes) => { let text = "";
    for (let i = 0; i < bytes.length; i += 32768) text += String.fromCharCode.apply(null, bytes.subarray(i, i + 32768));
    return btoa(text); };
  try { return [encode(handle.save_recording()), encode(handle.save_blueprint())]; } catch (error) { return null; }
}"""


def _free_ports() -> int:
    """A port P with P and P+1 free now (--web serves the page on P, the recordings' gRPC on P+1)."""
    while True:
        with socket.socket() as page, socket.socket() as grpc:
            page.bind(("127.0.0.1", 0))
            port = page.getsockname()[1]
            try:
                grpc.bind(("127.0.0.1", port + 1))
            except (OSError, OverflowError):
                continue
            return port


def _play(*args) -> subprocess.Popen:
    """robostrich-play in a process group of its own (the test can end it and its server whatever happens)."""
    return subprocess.Popen([conftest.console_script("robostrich-play"), *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=conftest.COMMAND_ENVIRONMENT,
                            start_new_session=True)


def _end(process: subprocess.Popen) -> None:
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()


def _served_url(process: subprocess.Popen, timeout: float = 300) -> str:
    """The URL from the line `serving ...` (read line by line; the command prints it once the page is up)."""
    deadline = time.monotonic() + timeout
    for line in process.stdout:
        found = re.search(r"(http://127\.0\.0\.1:\d+/\S*)", line) if line.startswith("serving ") else None
        if found:
            return found.group(1)
        assert time.monotonic() < deadline, "no `serving` line"
    raise AssertionError(f"robostrich-play ended ({process.wait()}) without serving: {process.stderr.read()[-3000:]}")


def _browser(playwright):
    if not CHROMIUM.exists():
        if os.environ.get("CI"):
            pytest.fail(f"{CHROMIUM} is missing on CI: .ci/run installs Debian's chromium before the tests")
        pytest.skip(f"{CHROMIUM} is not installed (apt-get install chromium): the web viewer is not tried in a browser")
    return playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS, headless=True)


def _loaded(page, tmp_path, timeout: float = 240) -> tuple:
    """(entities, view names) of the recording and layout the viewer holds, once the arm is among them."""
    deadline = time.monotonic() + timeout
    entities, views = set(), []
    while not ARM <= entities and time.monotonic() < deadline:
        saved = page.evaluate(SAVED)
        if saved:
            (tmp_path / "viewer.rrd").write_bytes(base64.b64decode(saved[0]))
            (tmp_path / "viewer.rbl").write_bytes(base64.b64decode(saved[1]))
            try:
                entities = conftest.rrd_entities(tmp_path / "viewer.rrd")
                views = conftest.rrd_view_names(tmp_path / "viewer.rbl")
            except ValueError:  # saved before the recording's first chunk arrived: not loaded yet
                pass
        time.sleep(1)
    return entities, views


@pytest.mark.long
def test_play_web_serves_the_recording_to_a_real_browser_and_stops_on_ctrl_c(tmp_path):
    playwright_api = pytest.importorskip("playwright.sync_api", reason="playwright is in the test extra")
    port = _free_ports()
    play = _play("--web", "--web-port", port, "--num-targets", 1, "--out", tmp_path / "play")
    try:
        url = _served_url(play)
        assert url == f"http://127.0.0.1:{port}/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A{port + 1}%2Fproxy", url
        with playwright_api.sync_playwright() as playwright:
            browser = _browser(playwright)
            page = browser.new_page(viewport={"width": 1400, "height": 900})
            page.goto(url)
            entities, views = _loaded(page, tmp_path)
            assert page.evaluate("() => window._handle.has_panicked()") is False
            page.screenshot(path=str(tmp_path / "web_viewer.png"))
            browser.close()
        assert ARM <= entities, sorted(entities)
        assert rerun_blueprint.ARM_VIEW in views and "Position error (m)" in views, views
        assert (tmp_path / "web_viewer.png").stat().st_size > 10_000
        play.send_signal(signal.SIGINT)
        assert play.wait(60) == 130
        assert play.stderr.read().strip().splitlines() == ["robostrich-play: interrupted"]
    finally:
        _end(play)


@pytest.mark.parametrize("taken_offset, what", [(0, ""), (1, " (PORT+1, the recordings' gRPC server)")],
                         ids=["page", "grpc"])
def test_a_taken_port_is_one_line_and_exit_2_before_any_work(tmp_path, taken_offset, what):
    port = _free_ports()
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", port + taken_offset))
        taken.listen()
        play = _play("--web", "--web-port", port, "--out", tmp_path / "play")
        try:
            stdout, stderr = play.communicate(timeout=300)
        finally:
            _end(play)
    assert play.returncode == 2, stderr[-3000:]
    assert stderr.splitlines() == [f"robostrich-play: error: --web-port {port}: 127.0.0.1:{port + taken_offset}{what} "
                                   "is taken (Address already in use); choose another port with --web-port"], stderr
    assert stdout == "" and not (tmp_path / "play").exists()


def test_web_with_no_recording_is_refused(tmp_path):
    refused = _play("--web", "--no-rerun", "--out", tmp_path / "play")
    stdout, stderr = refused.communicate(timeout=300)
    assert refused.returncode == 2 and stdout == "", stderr[-3000:]
    assert stderr.splitlines() == ["robostrich-play: error: --web serves the .rrd recordings, which --no-rerun "
                                   "turns off: drop one of them"], stderr


def test_a_killed_play_web_takes_its_server_with_it(tmp_path):
    """SIGKILL runs no cleanup in the command, yet its rerun server ends with it (Linux's parent-death
    signal), instead of listening on with no one left to stop it."""
    port = _free_ports()
    play = _play("--web", "--web-port", port, "--num-targets", 1, "--out", tmp_path / "play")
    try:
        _served_url(play)
        play.kill()  # the command alone: its server is in the same process group, and must go by itself
        play.wait(60)
        deadline = time.monotonic() + 30
        while any(_listening(p) for p in (port, port + 1)):
            assert time.monotonic() < deadline, "the web viewer's server outlived the command"
            time.sleep(0.2)
    finally:
        _end(play)
        try:
            os.killpg(play.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


def _listening(port: int) -> bool:
    with socket.socket() as probe:
        return probe.connect_ex(("127.0.0.1", port)) == 0
