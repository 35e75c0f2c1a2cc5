"""The package's layers (docs/ARCHITECTURE.md): every import points down, none closes a cycle, the engines are
reached through their interface alone, and every module and function stays small enough to read.

Every ``import`` and ``from ... import`` in the package's source is read, those inside functions
(lazy) and under ``if TYPE_CHECKING:`` included, and mapped to the shakermill module it names.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "src" / "shakermill"

# Bottom to top. A module may import from its own layer and from those below it.
LAYERS = ("support", "parameters", "physics", "engines", "analysis", "solvers", "io", "studies", "views", "cli")
# The package's __init__ is the facade above everything: it may import any layer, and none imports it.
FACADE = "shakermill"
LONGEST_FUNCTION_LINES = 80
LONGEST_MODULE_LINES = 700
# Each engine's own modules; the layers above the solvers reach an engine through engines/registry.py and
# engines/interface.py only.
ENGINE_PACKAGES = ("shakermill.engines.one_d", "shakermill.engines.dem")
ENGINE_BLIND_LAYERS = ("io", "studies", "views", "cli")


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def package_modules() -> dict[str, Path]:
    return {module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


MODULES = package_modules()


def imported_modules(name: str, path: Path) -> set[str]:
    """The shakermill modules that ``name`` imports, anywhere in its source."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, base] if base else anchor)
            # "from package import module" names a module; "from module import name" the module itself.
            targets = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in MODULES else base for alias in node.names]
        else:
            continue
        found.update(target for target in targets if target in MODULES and target != name)
    return found


GRAPH = {name: imported_modules(name, path) for name, path in MODULES.items()}


def layer_of(name: str) -> int:
    if name == FACADE:
        return len(LAYERS)
    return LAYERS.index(name.split(".")[1])


def test_every_module_belongs_to_a_layer():
    assert all(name == FACADE or name.split(".")[1] in LAYERS for name in MODULES), sorted(MODULES)


@pytest.mark.parametrize("name", sorted(MODULES))
def test_imports_point_down_the_layers(name):
    upward = sorted(target for target in GRAPH[name] if layer_of(target) > layer_of(name))
    assert upward == [], f"{name} imports from a layer above it: {upward}"


def test_no_module_imports_the_facade_but_the_facade_itself():
    assert [name for name, targets in GRAPH.items() if FACADE in targets] == []


def test_no_import_cycles():
    """Depth-first search for a back edge; the cycle found is printed whole."""
    state: dict[str, str] = {}
    stack: list[str] = []

    def visit(name: str) -> list[str] | None:
        state[name] = "open"
        stack.append(name)
        for target in sorted(GRAPH[name]):
            if state.get(target) == "open":
                return [*stack[stack.index(target) :], target]
            if target not in state and (cycle := visit(target)) is not None:
                return cycle
        stack.pop()
        state[name] = "done"
        return None

    for name in sorted(GRAPH):
        if name not in state:
            cycle = visit(name)
            assert cycle is None, " -> ".join(cycle)


def test_the_layering_test_sees_imports_inside_functions():
    # The command line imports the solvers only inside its commands (start-up); the walk must still see it.
    assert "shakermill.solvers.simulate" in GRAPH["shakermill.cli.common"]


def _in_package(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


def test_the_engines_do_not_import_each_other():
    crossing = [
        f"{name} -> {target}"
        for name in MODULES
        for own in ENGINE_PACKAGES
        if _in_package(name, own)
        for target in GRAPH[name]
        for other in ENGINE_PACKAGES
        if other != own and _in_package(target, other)
    ]
    assert crossing == []


def test_nothing_above_the_solvers_imports_a_specific_engine():
    direct = [
        f"{name} -> {target}"
        for name in MODULES
        if name != FACADE and name.split(".")[1] in ENGINE_BLIND_LAYERS
        for target in GRAPH[name]
        if any(_in_package(target, package) for package in ENGINE_PACKAGES)
    ]
    assert direct == []


def test_the_engine_check_sees_a_specific_engine_where_one_is_imported():
    # The solvers may name an engine (the lone impact runs the 'dem' engine): the check above must be able to see it.
    assert "shakermill.engines.dem.engine" in GRAPH["shakermill.solvers.impact"]


def test_no_module_is_longer_than_a_reader_can_hold():
    long = {
        name: lines
        for name, path in MODULES.items()
        if (lines := len(path.read_text(encoding="utf-8").splitlines())) > LONGEST_MODULE_LINES
    }
    assert long == {}


def body_lines(function: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """The lines of ``function``'s body after its docstring: what a reader must hold. The signature is left out, as
    the formatter writes a command's many options one per line."""
    body = function.body
    if len(body) > 1 and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        body = body[1:]
    return function.end_lineno - body[0].lineno + 1


def test_no_function_is_longer_than_a_reader_can_hold():
    long = [
        f"{name}.{node.name}: {body_lines(node)} lines"
        for name, path in MODULES.items()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and body_lines(node) > LONGEST_FUNCTION_LINES
    ]
    assert long == []
