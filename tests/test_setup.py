"""What setup.py promises matches what its pinned dependencies need, and the README says the same."""
import ast
import code
import contextlib
import importlib.metadata
import io
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]


def setup_arguments() -> dict:
    """The literal keyword arguments of setup() in setup.py."""
    tree = ast.parse((ROOT / "setup.py").read_text())
    call = next(node for node in ast.walk(tree) if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "setup")
    return {kw.arg: ast.literal_eval(kw.value) for kw in call.keywords
            if kw.arg in ("python_requires", "install_requires", "extras_require", "license", "classifiers",
                          "py_modules", "entry_points")}


def test_python_requires_is_what_the_pinned_dependencies_need():
    specifiers = pytest.importorskip("packaging.specifiers")
    version = pytest.importorskip("packaging.version")
    arguments = setup_arguments()
    floor = re.fullmatch(r">=(\d+\.\d+)", arguments["python_requires"])
    assert floor, arguments["python_requires"]
    lowest = version.Version(floor.group(1))
    pins = arguments["install_requires"] + [p for extra in arguments["extras_require"].values() for p in extra]
    needs = {}
    for pin in pins:
        name = re.split(r"[=<>!~\[ ]", pin, maxsplit=1)[0]
        try:
            requires = importlib.metadata.metadata(name).get("Requires-Python")
        except importlib.metadata.PackageNotFoundError:
            continue  # an extra that is not installed here
        if requires:
            needs[name] = requires
            assert lowest in specifiers.SpecifierSet(requires), (
                f"python_requires {arguments['python_requires']} but {pin} needs Python {requires}")
    assert needs, "no installed pin to check against"
    # ... and it is the tightest of them: python_requires claims no version none of them rules out.
    assert any(version.Version(f"{lowest.major}.{lowest.minor - 1}") not in specifiers.SpecifierSet(r)
               for r in needs.values()), (arguments["python_requires"], needs)


def test_the_licence_is_declared_and_shipped():
    arguments = setup_arguments()
    assert arguments["license"] == "Apache-2.0"
    assert "License :: OSI Approved :: Apache Software License" in arguments["classifiers"]
    assert "Apache License\n                           Version 2.0" in (ROOT / "LICENSE").read_text()


def test_readme_states_the_same_python_version():
    floor = setup_arguments()["python_requires"].removeprefix(">=")
    readme = (ROOT / "README.md").read_text()
    stated = set(re.findall(r"Python (\d+\.\d+)\+", readme))
    assert stated == {floor}, f"README says Python {stated}, setup.py {floor}+"


def test_readme_python_snippets_run_pasted_into_the_interpreter():
    """Each ```python block of the README, pasted line by line into Python's interactive prompt
    (where a loop needs a blank line after it), runs in a fresh namespace: it imports what it uses."""
    readme = (ROOT / "README.md").read_text()
    snippets = re.findall(r"```python\n(.*?)```", readme, flags=re.S)
    assert len(snippets) >= 2
    for number, snippet in enumerate(snippets, 1):
        console, shown = code.InteractiveConsole({}, filename=f"README.md python snippet {number}"), io.StringIO()
        with contextlib.redirect_stderr(shown), contextlib.redirect_stdout(io.StringIO()):
            waiting = False
            for line in snippet.splitlines():
                waiting = console.push(line)
            if waiting:
                console.push("")
        assert "Traceback" not in shown.getvalue() and "Error" not in shown.getvalue(), \
            f"README python snippet {number} fails at the prompt:\n{shown.getvalue()[-2000:]}"


def test_every_console_script_starts_from_the_launcher_beside_the_packages():
    """The suite's commands start from the suite's own modules, never through the agent: each console
    script is an entry of robostrich_commands, installed as a module of its own."""
    import robostrich_commands
    arguments = setup_arguments()
    assert arguments["py_modules"] == ["robostrich_commands"]
    scripts = dict(line.replace(" ", "").split("=") for line in arguments["entry_points"]["console_scripts"])
    assert set(scripts) == set(robostrich_commands.COMMANDS)
    for name, target in scripts.items():
        assert target == f"robostrich_commands:{name.removeprefix('robostrich-').replace('-', '_')}", name
    suite = {name for name, module in robostrich_commands.COMMANDS.items() if module.startswith("robostrich_suite.")}
    assert suite == {"robostrich-movement", "robostrich-workspace", "robostrich-targets", "robostrich-export-xml",
                     "robostrich-gait", "robostrich-walk", "robostrich-design"}
    assert all(module.startswith("agents.robostrich.") for name, module in robostrich_commands.COMMANDS.items()
               if name not in suite)
