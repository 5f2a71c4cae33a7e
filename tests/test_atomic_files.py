"""Outputs are written whole or not at all: an error while writing (a full disk included) leaves
the old file as it was and no partial file beside it, and names the file; any name the system
allows can be written; a location that cannot be written is refused before anything is made."""
import os
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from robostrich_suite import atomic_files  # noqa: E402


def test_an_error_mid_write_keeps_the_old_file_and_leaves_nothing_beside_it(tmp_path):
    path = tmp_path / "targets.npz"
    with atomic_files.replaced_atomically(path) as handle:
        np.savez_compressed(handle, head_position=np.ones((3, 2)))
    before = path.read_bytes()
    with pytest.raises(RuntimeError, match="disk full"):
        with atomic_files.replaced_atomically(path) as handle:
            handle.write(b"half a file")
            raise RuntimeError("disk full")
    assert path.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["targets.npz"]
    np.testing.assert_array_equal(np.load(path)["head_position"], np.ones((3, 2)))


def test_figures_and_text_land_whole_with_ordinary_permissions(tmp_path):
    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    png = atomic_files.save_figure(fig, tmp_path / "sub" / "plot.png", dpi=50)
    plt.close(fig)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and (png.stat().st_mode & 0o777) == 0o644
    atomic_files.write_text(tmp_path / "table.md", "| a |\n")
    assert (tmp_path / "table.md").read_text() == "| a |\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sub", "table.md"]


def test_a_write_that_cannot_land_names_the_path_asked_for_not_the_temporary_file(tmp_path):
    directory = tmp_path / "a_directory"
    directory.mkdir()
    with pytest.raises(IsADirectoryError) as caught:
        atomic_files.write_text(directory, "text")
    assert caught.value.filename == str(directory)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_directory"]  # no partial file left


def test_a_recording_is_written_whole_or_not_at_all(tmp_path):
    from robostrich_suite import rerun_log
    path = tmp_path / "rollout.rrd"
    with pytest.raises(KeyboardInterrupt):
        with rerun_log.recording("test", path) as rec:
            rerun_log.log_scalars(rec, "plots", {"x": 1.0})
            raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []
    with rerun_log.recording("test", path) as rec:
        rerun_log.log_scalars(rec, "plots", {"x": 1.0})
    assert [p.name for p in tmp_path.iterdir()] == ["rollout.rrd"] and path.stat().st_size > 0


@pytest.mark.parametrize("name", ["a" * 246 + ".csv", "\u00e9" * 123 + ".csv", "b" * 255])
def test_a_name_of_up_to_255_bytes_is_written_under_a_temporary_name_that_fits(tmp_path, name):
    """The temporary name (``.NAME.XXXXXXXX.partial``) of a long name is shortened, on a character's
    boundary, instead of failing with "File name too long"."""
    path = tmp_path / name
    atomic_files.write_text(path, "x\n")
    assert path.read_text() == "x\n" and [p.name for p in tmp_path.iterdir()] == [name]
    prefix = atomic_files.temporary_prefix(name)
    assert len(prefix.encode()) + 8 + len(".partial") <= 255 and prefix.startswith("." + name[:10])
    assert atomic_files.temporary_prefix("walk.rrd") == ".walk.rrd."  # short names keep the readable form


def test_a_write_that_fails_names_the_file_and_leaves_nothing(tmp_path):
    """A full disk (here a file size limit, which Python turns into "File too large") mid-write
    names the path asked for, not the temporary file nor no file at all."""
    import resource
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    path = tmp_path / "big.bin"
    resource.setrlimit(resource.RLIMIT_FSIZE, (4096, hard))
    try:
        with pytest.raises(OSError) as caught:
            with atomic_files.replaced_atomically(path) as handle:
                handle.write(b"x" * 100_000)
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
    assert caught.value.filename == str(path) and caught.value.strerror == "File too large"
    assert list(tmp_path.iterdir()) == []


def test_an_error_about_another_file_inside_the_block_keeps_its_own_name(tmp_path):
    with pytest.raises(FileNotFoundError) as caught:
        with atomic_files.replaced_atomically(tmp_path / "out.txt", "w") as handle:
            handle.write(open(tmp_path / "missing.txt").read())
    assert caught.value.filename == str(tmp_path / "missing.txt") and list(tmp_path.iterdir()) == []


def test_output_locations_are_checked_without_making_anything(tmp_path):
    from robostrich_suite import outputs
    regular = tmp_path / "somefile.txt"
    regular.write_text("")
    deep = pathlib.Path(*["d"] * 2100)  # 4199 bytes: over PATH_MAX
    cases = [(outputs.check_directory, tmp_path / deep, "bytes long"),
             (outputs.check_file, tmp_path / ("n" * 256) / "t.npz", "over the 255"),
             (outputs.check_directory, regular / "sub", "somefile.txt is a file"),
             (outputs.check_file, regular / "sub" / "t.npz", "somefile.txt is a file"),
             (outputs.check_directory, regular, "is a file, not a directory"),
             (outputs.check_file, tmp_path, "is a directory, not a file")]
    for check, path, fragment in cases:
        with pytest.raises(OSError, match=fragment) as caught:
            check(path)
        assert "--out" in str(caught.value) and len(str(caught.value)) < 400  # one readable line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["somefile.txt"]
    assert outputs.check_directory(tmp_path / "new" / "dir") == tmp_path / "new" / "dir"
    assert outputs.check_file(tmp_path / "new" / ("f" * 255)).name == "f" * 255
    assert sorted(p.name for p in tmp_path.iterdir()) == ["somefile.txt"]


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes in a read-only directory: nothing to refuse")
def test_a_directory_without_write_permission_is_refused_before_anything_is_made(tmp_path):
    from robostrich_suite import outputs
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o555)
    with pytest.raises(PermissionError, match="cannot write in"):
        outputs.check_directory(locked / "sub")
    with pytest.raises(PermissionError, match="cannot write in"):
        outputs.check_file(locked / "t.npz")
    assert list(locked.iterdir()) == []
