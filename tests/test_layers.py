"""The package's layers import downwards only: model -> physics -> tasks -> domains, the suite a
simulation user loads; above it the command kit (flags, outputs, progress, workers, the viewer) and
the studies; and robostrich_suite never imports the agent (a simulation user needs no JAX)."""
import ast
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "robostrich_suite"
# Each module's layer; a module may import from its own layer and the ones below it. The suite is
# utilities to domains: it never imports the command kit or the studies.
LAYERS = ("utilities", "model", "physics", "tasks", "domains", "commands", "studies")
TOP_LEVEL = {"atomic_files": "utilities", "input_files": "utilities", "parsing": "utilities",
             "targets": "model", "physics": "physics", "quadruped_physics": "physics", "scenes": "physics",
             "fingerprint": "physics", "robostrich": "domains", "robostrich_a1": "domains",
             "gym_adapter": "domains", "policies": "domains", "__init__": "domains",
             "cli": "commands", "outputs": "commands", "progress": "commands", "parallel": "commands",
             "web_viewer": "commands", "rerun_log": "commands", "rerun_blueprint": "commands",
             "speed_benchmarks": "commands", "export_xml": "commands"}


def layer_of(module: str) -> str:
    parts = module.split(".")[1:] or ["__init__"]
    if parts[0] in ("model", "tasks", "studies"):
        return parts[0]
    return TOP_LEVEL[parts[0]]


def modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        name = ".".join(path.relative_to(ROOT).with_suffix("").parts)
        yield name.removesuffix(".__init__"), path


def imported(path: pathlib.Path):
    """Every robostrich_suite or agents module `path` imports, at any depth (inside functions too)."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            yield from (a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            if node.module == "robostrich_suite":
                yield from (f"robostrich_suite.{a.name}" for a in node.names)
            else:
                yield node.module


def test_every_module_has_a_layer():
    for module, _ in modules():
        assert layer_of(module) in LAYERS, module


def test_no_module_imports_a_higher_layer_or_the_agent():
    wrong = []
    for module, path in modules():
        own = LAYERS.index(layer_of(module))
        for target in imported(path):
            if target.split(".")[0] == "agents":
                wrong.append(f"{module} imports {target}")
            elif target.startswith("robostrich_suite") and target != "robostrich_suite":
                if LAYERS.index(layer_of(target)) > own:
                    wrong.append(f"{module} ({layer_of(module)}) imports {target} ({layer_of(target)})")
            elif target == "robostrich_suite" and own < LAYERS.index("domains"):
                wrong.append(f"{module} imports the package's top")
    assert not wrong, "\n".join(wrong)


def test_every_module_imports_with_the_agent_blocked():
    """A user of the simulation alone: with `agents` unimportable, every module still imports."""
    names = [m for m, _ in modules()]
    code = ("import sys\nclass Block:\n    def find_spec(self, name, path=None, target=None):\n"
            "        if name == 'agents' or name.startswith('agents.'):\n"
            "            raise ImportError('agents is blocked')\n"
            "sys.meta_path.insert(0, Block())\nimport importlib\n"
            f"for name in {names!r}:\n    importlib.import_module(name)\nprint('imported', len({names!r}))\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT,
                            env={"MUJOCO_GL": "egl", "PATH": "/usr/bin:/bin"})
    assert result.returncode == 0, result.stderr[-2000:]
    assert f"imported {len(names)}" in result.stdout


def test_the_command_launcher_belongs_to_neither_package_and_imports_only_the_standard_library():
    """robostrich_commands.py, beside both packages, imports importlib, os, signal and sys (anywhere in
    the file) and names each command's module as text: importing it loads neither package, and each
    command's module is a file of its own package."""
    launcher = ROOT / "robostrich_commands.py"
    assert set(imported(launcher)) == {"importlib", "os", "signal", "sys"}
    table = next(node.value for node in ast.parse(launcher.read_text()).body
                 if isinstance(node, ast.Assign) and [t.id for t in node.targets] == ["COMMANDS"])
    for prog, target in ast.literal_eval(table).items():
        module = target.split(":")[0].split(".")
        assert module[0] in ("robostrich_suite", "agents"), target
        assert ROOT.joinpath(*module).with_suffix(".py").exists(), target
        # named after the command: robostrich-export-xml in .../export_xml.py or .../export_xml/command.py
        word = prog.removeprefix("robostrich-").replace("-", "_")
        assert module[-1] == word or module[-2:] == [word, "command"], (prog, target)


@pytest.mark.parametrize("module", ["robostrich_suite.model.arm", "robostrich_suite.physics"])
def test_layer_map_is_not_vacuous(module):
    assert layer_of(module) in ("model", "physics")


def test_a_figure_module_imports_nothing_of_its_study():
    """A study imports its figure module, never the reverse (no loop: the figure reads the study's results)."""
    figures = {m: p for m, p in modules() if m.startswith("robostrich_suite.studies.") and m.endswith("_figure")}
    assert "robostrich_suite.studies.movement_figure" in figures and "robostrich_suite.studies.workspace_figure" in figures
    loops = [f"{m} imports {t}" for m, p in figures.items() for t in imported(p) if t == m.removesuffix("_figure")]
    assert not loops, "\n".join(loops)


def test_tools_find_the_packages_by_their_install():
    """tools/ scripts import the installed packages (pip install -e .): none edits sys.path by hand."""
    editing = [p.name for p in sorted((ROOT / "tools").glob("*.py")) if "sys.path" in p.read_text()]
    assert not editing, editing


# The agent's imports of the project's own modules stand at the top of each module, where a reader
# sees what it depends on; these stay inside functions because they pull in a library only some
# commands need (rerun for recordings, gymnasium for the peer agents).
LAZY_IMPORTS = {("agents/robostrich/recording.py", "robostrich_suite.rerun_log"),
                ("agents/robostrich/recording.py", "robostrich_suite.rerun_blueprint"),
                ("agents/robostrich/peers/sbx_agents.py", "robostrich_suite.gym_adapter")}


def test_the_agent_imports_the_projects_modules_at_the_top():
    hidden = set()
    for path in sorted((ROOT / "agents").rglob("*.py")):
        where = path.relative_to(ROOT).as_posix()
        functions = [n for n in ast.walk(ast.parse(path.read_text())) if isinstance(n, ast.FunctionDef)]
        for node in (sub for function in functions for sub in ast.walk(function)):
            if isinstance(node, ast.ImportFrom) and node.module:
                targets = {node.module} | {f"{node.module}.{a.name}" for a in node.names}
            elif isinstance(node, ast.Import):
                targets = {a.name for a in node.names}
            else:
                continue
            own = {t for t in targets if t.split(".")[0] in ("agents", "robostrich_suite")}
            if own and not any((where, t) in LAZY_IMPORTS for t in own):
                hidden.add(f"{where}:{node.lineno} imports {min(own)} inside a function")
    assert not hidden, "\n".join(sorted(hidden))


def project_modules() -> dict:
    """Every module of both packages: its dotted name -> its file."""
    found = {}
    for package in ("robostrich_suite", "agents"):
        for path in sorted((ROOT / package).rglob("*.py")):
            found[".".join(path.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")] = path
    return found


def import_circles(graph: dict) -> list:
    """The groups of modules that import each other round a circle (strongly connected, more than
    one module), each sorted; an iterative Tarjan, so that a deep chain needs no recursion."""
    index, low, on_stack, stack, circles = {}, {}, set(), [], []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, targets = work[-1]
            target = next(targets, None)
            if target is not None:
                if target not in index:
                    index[target] = low[target] = len(index)
                    stack.append(target)
                    on_stack.add(target)
                    work.append((target, iter(sorted(graph[target]))))
                elif target in on_stack:
                    low[node] = min(low[node], index[target])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                group = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    group.append(member)
                    if member == node:
                        break
                if len(group) > 1:
                    circles.append(sorted(group))
    return circles


def test_the_circle_finder_finds_a_circle_and_nothing_else():
    assert import_circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert import_circles({"a": {"b"}, "b": set()}) == []


def test_no_two_modules_import_each_other_even_inside_functions():
    """An import circle, even through a function-level import, ties modules that should be read
    (and changed) one after the other; none of either package has one."""
    found = project_modules()
    graph = {}
    for module, path in found.items():
        targets = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                targets.update(a.name for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module:
                targets.update(f"{node.module}.{a.name}" if f"{node.module}.{a.name}" in found else node.module
                               for a in node.names)
        graph[module] = {t for t in targets if t in found and t != module}
    assert import_circles(graph) == []


# The project's own modules a function may import instead of its module, and why.
FUNCTION_LEVEL_IMPORTS = {
    ("agents/robostrich/peers/sbx_agents.py", "robostrich_suite.gym_adapter"):
        "gymnasium, which the adapter needs, comes with the optional sbx extra only",
}


def test_the_projects_own_modules_are_imported_at_the_top_of_a_module():
    """A module's imports at its top say what it needs; a function-level import of the project's
    own code hides a dependency (and once hid an import circle), so only the listed ones stay."""
    found = set()
    for package in ("robostrich_suite", "agents", "tools"):
        for path in sorted((ROOT / package).rglob("*.py")):
            for function in ast.walk(ast.parse(path.read_text())):
                if not isinstance(function, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    continue
                for node in ast.walk(function):
                    names = ([node.module] if isinstance(node, ast.ImportFrom) and node.module else
                             [a.name for a in node.names] if isinstance(node, ast.Import) else [])
                    found.update((str(path.relative_to(ROOT)), name) for name in names
                                 if name.split(".")[0] in ("robostrich_suite", "agents"))
    assert found == set(FUNCTION_LEVEL_IMPORTS), sorted(found - set(FUNCTION_LEVEL_IMPORTS))
