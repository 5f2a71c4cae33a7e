"""An arm described in a file (robostrich_suite/model/arm_file.py): Table 1's file is Table 1's arm
and writes the checked-in models; a changed field reaches the model; a file that cannot be an arm is
one line naming the field, exit status 2."""
import os
import re

import pytest

from conftest import ROOT, run_in_one_process
from robostrich_suite.model import arm as arm_lib
from robostrich_suite.model import arm_file, layouts

TABLE1 = arm_file.SHIPPED_DIR / "robostrich.toml"


def test_table1s_file_is_table1s_arm_and_is_what_the_writer_writes():
    arm = arm_file.read(TABLE1)
    assert arm.name == "robostrich" and arm.spec == arm_lib.ArmSpec.from_table1() and arm.routing == layouts.DEFAULT
    assert arm.layout == layouts.build(layouts.DEFAULT)
    assert arm_file.text("robostrich", arm.spec) == TABLE1.read_text()


def _with(tmp_path, name: str, old: str, new: str):
    """Table 1's file with ``old`` replaced by ``new`` (a regular expression), as ``name``.toml."""
    changed, count = re.subn(old, new, TABLE1.read_text(), count=1, flags=re.M)
    assert count == 1, old
    path = tmp_path / f"{name}.toml"
    path.write_text(changed)
    return path


def test_the_command_writes_an_arms_models_and_refuses_a_bad_file_in_one_line(tmp_path):
    stiff = _with(tmp_path, "stiff", r'^name = "robostrich"', 'name = "stiff"')
    stiff.write_text(stiff.read_text().replace("joint_stiffness = 1.0", "joint_stiffness = 2.5"))
    routing = tmp_path / "routing.toml"
    routing.write_text('[[tendons]]\nname = "t"\nside = "ventral"\nlinks = ["c20", "atlas"]\n')
    bad = {
        "negative length": (_with(tmp_path, "a", r"link_lengths = \[0\.0070999999999999995", "link_lengths = [-0.007"),
                            "arm: link 'c2': length -0.007 m must be positive"),
        "limit": (_with(tmp_path, "b", r"dorsal_limits_deg = \[1\.0", "dorsal_limits_deg = [190.0"),
                  "arm: joint 'atlas': dorsal limit 190.0 deg must be in [0, 180)"),
        "counts": (_with(tmp_path, "c", r"masses = \[0\.083, ", "masses = ["),
                   "arm: masses has 17 entries, expected 18"),
        "unknown field": (_with(tmp_path, "d", r"^head_length", "head_lenght"), "arm.head_lenght: unknown field"),
        "type": (_with(tmp_path, "e", r"^tendon_kp = 4000\.0", 'tendon_kp = "stiff"'),
                 "arm.tendon_kp: must be a number, got 'stiff'"),
        "routing": (_with(tmp_path, "f", r'^layout = "ventral_slips"', 'file = "routing.toml"'),
                    "routing.file: 'routing.toml' does not fit this arm"),
        "not toml": (_with(tmp_path, "g", r"^\[arm\]", "[arm"), "not valid TOML"),
        "fifo": (tmp_path / "fifo.toml", "a FIFO, not a text file"),  # refused at once, never waited on
    }
    os.mkfifo(tmp_path / "fifo.toml")
    cases = {"stiff": ("robostrich-export-xml", ["--arm", stiff, "--out", tmp_path / "xml"]),
             "table1": ("robostrich-export-xml", ["--arm", TABLE1, "--out", tmp_path / "table1"])}
    cases.update({name: ("robostrich-export-xml", ["--arm", path, "--out", tmp_path / name.replace(" ", "_")])
                  for name, (path, _) in bad.items()})
    results = run_in_one_process(cases)
    for name in ("table1", "stiff"):
        assert results[name].returncode == 0, results[name].stderr
    for model in ("robostrich.xml", "robostrich_a1.xml"):  # Table 1's file: the checked-in models, byte for byte
        assert (tmp_path / "table1" / model).read_text() == (ROOT / "xml" / model).read_text()
    written = (tmp_path / "xml" / "stiff.xml").read_text()
    assert sorted(p.name for p in (tmp_path / "xml").iterdir()) == ["stiff.xml", "stiff_a1.xml"]
    assert written != (ROOT / "xml" / "robostrich.xml").read_text() and 'stiffness="2.5"' in written
    for name, (path, message) in bad.items():
        lines = results[name].stderr.strip().splitlines()
        assert results[name].returncode == 2 and len(lines) == 1, (name, results[name].stderr)
        assert lines[0].startswith(f"robostrich-export-xml: error: {path}: ") and message in lines[0], (name, lines)
        assert not (tmp_path / name.replace(" ", "_")).exists()  # refused before anything is written


def test_a_missing_routing_key_or_name_is_named():
    with pytest.raises(arm_file.ArmFileError, match="routing: must be one of"):
        arm_file._routing({"layout": "ventral_slips", "file": "x"}, arm_lib.ArmSpec.from_table1(), TABLE1,
                          arm_file._failer(TABLE1))
    with pytest.raises(arm_file.ArmFileError, match="routing.layout: 'nope' does not fit this arm: unknown layout"):
        arm_file._routing({"layout": "nope"}, arm_lib.ArmSpec.from_table1(), TABLE1, arm_file._failer(TABLE1))
