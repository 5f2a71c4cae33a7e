"""The code's shape: generic modules that name no robot, no function longer than a screen, no module
over 500 lines. (How a checkpoint of an earlier format is read: tests/test_run_spec.py and
tests/test_learner_layout.py.)"""
import ast
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[1]
GENERIC = sorted(p for p in (ROOT / "agents").rglob("*.py") if "robostrich" not in p.relative_to(ROOT).parts)
# Words of the robot and its simulator that a generic agent has no business knowing.
ROBOT_WORDS = re.compile(r"robostrich|mujoco|dm_control|tendon|trunk|geom|quadruped|lookup", re.IGNORECASE)
MAX_FUNCTION_LINES = 60
MAX_MODULE_LINES = 500  # a module past this holds more than one job
# Both packages and the console scripts' launcher beside them.
PROJECT_MODULES = sorted([*(ROOT / "agents").rglob("*.py"), *(ROOT / "robostrich_suite").rglob("*.py"),
                          ROOT / "robostrich_commands.py"])


def test_generic_agent_modules_name_no_robot_and_import_no_simulator():
    assert len(GENERIC) >= 10, [p.name for p in GENERIC]  # sac/*, actors, replay, loop, curriculum, ...
    found = [f"{p.relative_to(ROOT)}:{n}: {line.strip()}" for p in GENERIC
             for n, line in enumerate(p.read_text().splitlines(), 1) if ROBOT_WORDS.search(line)]
    assert not found, "\n".join(found)


def test_no_function_is_longer_than_a_screen():
    long = []
    for path in PROJECT_MODULES:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_FUNCTION_LINES:
                    long.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name}: {lines} lines")
    assert not long, "\n".join(long)


def test_no_module_is_longer_than_its_one_job_needs():
    long = [f"{path.relative_to(ROOT)}: {n} lines" for path in PROJECT_MODULES
            if (n := len(path.read_text().splitlines())) > MAX_MODULE_LINES]
    assert not long, "\n".join(long)
