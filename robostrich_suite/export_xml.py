"""The generated MJCF of the default models, as checked in under ``xml/``, or of an arm described
in a file (``--arm FILE``, robostrich_suite/model/arm_file.py): the arm on its frame and on the quadruped.

``xml/`` lets a user open the robots in plain MuJoCo (``simulate``,
``mujoco.MjModel.from_xml_path``) without this package.  A test fails when a
checked-in file differs from what the generators produce now; regenerate from the
repository's root with ``robostrich-export-xml --out xml``.
"""
from __future__ import annotations

import pathlib

from robostrich_suite import atomic_files
from robostrich_suite import cli as cli_lib
from robostrich_suite import outputs
from robostrich_suite import robostrich
from robostrich_suite import robostrich_a1
from robostrich_suite.model import arm_file


def _robostrich():
    return robostrich.get_model_and_assets()[0]


def _robostrich_a1():
    return robostrich_a1.get_model_and_assets()[0]


def generators(arm: arm_file.ArmFile | None = None) -> dict:
    """File name -> function returning that model's XML string: the default models, or ``arm``'s
    (named after it) on the frame and on the quadruped."""
    if arm is None:
        return {"robostrich.xml": _robostrich, "robostrich_a1.xml": _robostrich_a1}
    return {f"{arm.name}.xml": lambda: robostrich.get_model_and_assets(arm.spec, arm.layout)[0],
            f"{arm.name}_a1.xml": lambda: robostrich_a1.get_model_and_assets(arm.spec, arm.layout)[0]}


def export(directory: pathlib.Path, arm: arm_file.ArmFile | None = None) -> list[pathlib.Path]:
    """Write every model's XML (the default ones, or ``arm``'s) into ``directory``; returns the paths."""
    directory = pathlib.Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for name, generate in generators(arm).items():
        path = directory / name
        atomic_files.write_text(path, generate())
        written.append(path)
    return written


def main(argv=None) -> None:
    parser = cli_lib.Parser(description="Write the generated MJCF of the default models, or of an arm in a file.")
    parser.add_argument("--out", type=pathlib.Path, required=True,
                        help="directory to write into (the checked-in copies: the repository's xml/)")
    parser.add_argument("--arm", type=pathlib.Path, default=None,
                        help="an arm file (TOML: every field of the arm and its routing; Table 1's: "
                             "robostrich_suite/data/arms/robostrich.toml): write NAME.xml and NAME_a1.xml of that arm "
                             "(default: the default models)")
    args = parser.parse_args(argv)
    arm = None if args.arm is None else arm_file.read(args.arm)  # a bad file: one line before anything is written
    outputs.check_directory(args.out)
    for path in export(args.out, arm):
        print(f"wrote {path}")


def cli(argv=None) -> int:
    """Console script `robostrich-export-xml`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-export-xml", argv)


if __name__ == "__main__":
    import sys
    sys.exit(cli())
