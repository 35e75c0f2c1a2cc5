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


# The floors of the studies (docs/ARCHITECTURE.md), bottom to top: a floor imports from its own and those below.
STUDIES_FLOORS = ("measured", "sweeps", "inference", "calibration", "ensembles", "validation")


def test_the_studies_floors_import_down_only():
    floor_of = {name: STUDIES_FLOORS.index(name.split(".")[2]) for name in MODULES if name.count(".") >= 2
                and name.startswith("shakermill.studies.")}  # fmt: skip
    assert sorted({name.split(".")[2] for name in floor_of}) == sorted(STUDIES_FLOORS)
    upward = [
        f"{name} -> {target}"
        for name, floor in floor_of.items()
        for target in GRAPH[name]
        if target in floor_of and floor_of[target] > floor
    ]
    assert upward == []


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


# The run summary's schema (issue 39): the one module that may read a summary by a key's name.
SUMMARY_SCHEMA = "shakermill.solvers.summary"
# What reading by a string looks like: a method of a dict that takes a key, or getattr with a name.
KEYED_METHODS = {"get", "pop", "setdefault", "update", "__getitem__", "__contains__"}
FUNCTIONS = (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)


def _is_summary(node: ast.AST, aliases: set[str]) -> bool:
    """Whether ``node`` is a run summary: ``<anything>.summary``, a name ``summary``, or a name bound to one."""
    if isinstance(node, ast.Attribute):
        return node.attr == "summary"
    return isinstance(node, ast.Name) and (node.id == "summary" or node.id in aliases)


def _names_summary(annotation: ast.AST | None) -> bool:
    """Whether an annotation names the ``Summary`` type (``Summary``, ``Summary | None``, ``"Summary"``)."""
    if annotation is None:
        return False
    text = annotation.value if isinstance(annotation, ast.Constant) else ast.unparse(annotation)
    return "Summary" in str(text).replace("|", " ").split() or str(text) == "Summary"


def _bound_targets(target: ast.AST, value: ast.AST) -> list[tuple[ast.AST, ast.AST]]:
    """The (name, value) pairs of an assignment, tuples unpacked element by element (``a, b = x.summary, y``)."""
    if isinstance(target, ast.Tuple) and isinstance(value, ast.Tuple) and len(target.elts) == len(value.elts):
        return [pair for t, v in zip(target.elts, value.elts) for pair in _bound_targets(t, v)]
    return [(target, value)]


def _own_nodes(scope: ast.AST) -> list[ast.AST]:
    """The nodes of ``scope`` (a module or a function) but those of the functions nested in it: scopes of their own."""
    nodes, stack = [], list(ast.iter_child_nodes(scope))
    while stack:
        node = stack.pop()
        nodes.append(node)
        if not isinstance(node, FUNCTIONS):
            stack.extend(ast.iter_child_nodes(node))
    return nodes


def summary_aliases(scope: ast.AST, inherited: set[str]) -> set[str]:
    """The names that hold a run summary in ``scope`` (a module or a function; a nested function inherits those of
    the scopes around it): its parameters annotated ``Summary`` and the names assigned one (``s = result.summary``,
    ``t = s``), to a fixpoint."""
    aliases = set(inherited)
    if isinstance(scope, FUNCTIONS):
        arguments = scope.args
        every = [*arguments.posonlyargs, *arguments.args, *arguments.kwonlyargs, arguments.vararg, arguments.kwarg]
        aliases |= {arg.arg for arg in every if arg is not None and _names_summary(arg.annotation)}
    assignments = []
    for node in _own_nodes(scope):
        if isinstance(node, ast.Assign):
            assignments += [pair for target in node.targets for pair in _bound_targets(target, node.value)]
        elif isinstance(node, (ast.AnnAssign, ast.NamedExpr)) and node.value is not None:
            assignments.append((node.target, node.value))
            if (
                isinstance(node, ast.AnnAssign)
                and isinstance(node.target, ast.Name)
                and _names_summary(node.annotation)
            ):
                aliases.add(node.target.id)
    while True:
        bound = {
            target.id
            for target, value in assignments
            if isinstance(target, ast.Name) and _is_summary(value, aliases) and target.id not in aliases
        }
        if not bound:
            return aliases
        aliases |= bound


def _string_read(node: ast.AST, aliases: set[str]) -> bool:
    """Whether ``node`` reads a summary by a key given as a string (or chosen at run time): a subscript of it, one of
    its :data:`KEYED_METHODS`, ``getattr(summary, name)``, or ``name in summary``."""
    if isinstance(node, ast.Subscript):
        return _is_summary(node.value, aliases)
    if isinstance(node, ast.Compare):
        return any(
            isinstance(op, (ast.In, ast.NotIn)) and _is_summary(right, aliases)
            for op, right in zip(node.ops, node.comparators)
        )
    if not isinstance(node, ast.Call):
        return False
    function = node.func
    if isinstance(function, ast.Attribute) and function.attr in KEYED_METHODS:
        return _is_summary(function.value, aliases)
    if isinstance(function, ast.Name) and function.id in {"getattr", "hasattr"} and node.args:
        return _is_summary(node.args[0], aliases)
    return False


def summary_string_reads(source: str) -> list[str]:
    """Where ``source`` reads a run summary by a string key, as 'line N: <the expression>'."""
    tree = ast.parse(source)
    found: list[str] = []

    def visit(scope: ast.AST, inherited: set[str]) -> None:
        aliases = summary_aliases(scope, inherited)
        for node in ast.iter_child_nodes(scope):
            walk(node, aliases)

    def walk(node: ast.AST, aliases: set[str]) -> None:
        if isinstance(node, FUNCTIONS):
            visit(node, aliases)
            return
        if _string_read(node, aliases):
            found.append(f"line {node.lineno}: {ast.unparse(node)}")
        for child in ast.iter_child_nodes(node):
            walk(child, aliases)

    visit(tree, set())
    return found


SUMMARY_READS_SAMPLE = """
def headline(result, run):
    ball = result.summary["ball_C"]
    vial = summary.get("x")
    s = run.summary
    air = s['air_C']
    t = s
    rate = t.get(f"{name}_hz")
    tau = getattr(result.summary, "tau_min")
    key = "ball_steady_C"
    steady = run.summary[key]
    run.summary["validation_caveat"] = "said"
    full, averaged = a.summary, b.summary
    return averaged["heat_power_W"] if "holder_C" in run.summary else None


def interval_rows(s: Summary | None) -> float:
    return s[f"{node}_C"]


def nested(result):
    s = result.summary

    def inner():
        return s["ball_C"]

    return inner
"""
SUMMARY_READS_ALLOWED = """
def elsewhere(result):
    s = result.summary
    return s.ball_C


def headline(result, document, row, s, table):
    a = result.summary.ball_C
    b = result.summary.value("ball_steady_C")
    c = document["summary"]
    d = row["ball_C"]
    e = s["ball_C"]  # this s is no summary
    f = result.summary.heat_paths_W["ball → air"]
    g = result.summary.heat_by_channel_W.get("normal")
    h = table[declared_name("ball_C")]
    return steady.as_summary()["ball_steady_C"]
"""


def test_the_summary_read_check_sees_every_way_of_reading_a_summary_by_a_string():
    found = summary_string_reads(SUMMARY_READS_SAMPLE)
    assert [line.split(":")[0] for line in found] == [f"line {n}" for n in (3, 4, 6, 8, 9, 11, 12, 14, 14, 18, 25)], (
        found
    )
    assert "line 3: result.summary['ball_C']" in found
    assert "line 4: summary.get('x')" in found
    assert summary_string_reads(SUMMARY_READS_ALLOWED) == []


def test_no_module_but_the_schema_reads_a_summary_by_a_string():
    """Every reader goes through ``solvers/summary.py``: attributes (``result.summary.ball_C``), or
    ``summary.value(name)`` where the key is chosen at run time, which refuses a name the schema does not declare."""
    found = {
        name: reads
        for name, path in MODULES.items()
        if name != SUMMARY_SCHEMA and (reads := summary_string_reads(path.read_text(encoding="utf-8")))
    }
    assert found == {}


# No branch on an engine's name above the engines (issue 39): a layer that differs by engine asks what the engine
# declares (its description, its keys, its capabilities). Constructing a run of an engine by name stays allowed.
ENGINES_PACKAGE = "shakermill.engines"
BUILT_IN_ENGINES = frozenset({"1d", "dem"})
ENGINE_NAME_HOLDERS = {"engine", "engine_name"}
ENGINE_OWNERS = {"description", "keys", "engine_keys"}


def _names_an_engine(node: ast.AST) -> bool:
    """Whether ``node`` holds an engine's name: ``<x>.engine``, a name ``engine``, ``<x>["engine"]`` (``.value`` of
    either), or the ``name`` of an engine's description or keys."""
    if isinstance(node, ast.Attribute) and node.attr == "value":
        node = node.value
    if isinstance(node, ast.Attribute):
        if node.attr in ENGINE_NAME_HOLDERS:
            return True
        owner = node.value
        owned = owner.attr if isinstance(owner, ast.Attribute) else getattr(owner, "id", None)
        return node.attr == "name" and owned in ENGINE_OWNERS
    if isinstance(node, ast.Name):
        return node.id in ENGINE_NAME_HOLDERS
    return isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant) and node.slice.value == "engine"


def _strings(node: ast.AST) -> list[str]:
    """The string literals ``node`` is or holds: a string, a tuple, list or set of them, a dict's keys."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [node.value]
    elements = node.keys if isinstance(node, ast.Dict) else getattr(node, "elts", [])
    if not isinstance(node, (ast.Tuple, ast.List, ast.Set, ast.Dict)):
        return []
    return [
        element.value for element in elements if isinstance(element, ast.Constant) and isinstance(element.value, str)
    ]


def _branches_on_an_engine_name(node: ast.AST) -> bool:
    """A comparison of an engine's name with a string literal (``params.engine == "dem"``, ``!= "1d"``, ``in (...)``)
    or of anything with a built-in engine's name; a ``match`` on an engine's name or with a case of one; a dict
    literal indexed by an engine's name."""
    if isinstance(node, ast.Compare):
        sides = [node.left, *node.comparators]
        literal = [side for side in sides if _strings(side)]
        named = any(_names_an_engine(side) for side in sides)
        return bool(literal) and (named or any(set(_strings(side)) & BUILT_IN_ENGINES for side in literal))
    if isinstance(node, ast.Match):
        values = [pattern for case in node.cases for pattern in ast.walk(case.pattern)]
        constants = {pattern.value.value for pattern in values if isinstance(pattern, ast.MatchValue)}
        return _names_an_engine(node.subject) or bool(constants & BUILT_IN_ENGINES)
    return isinstance(node, ast.Subscript) and isinstance(node.value, ast.Dict) and _names_an_engine(node.slice)


def engine_name_branches(source: str) -> list[str]:
    """Where ``source`` branches on an engine's name, as 'line N: <the expression>'."""
    found = [node for node in ast.walk(ast.parse(source)) if _branches_on_an_engine_name(node)]
    found.sort(key=lambda node: (node.lineno, node.col_offset))
    return [f"line {node.lineno}: {ast.unparse(node).splitlines()[0]}" for node in found]


ENGINE_BRANCHES_SAMPLE = """
def guarded(params, result, description, preset, kind):
    if params.engine != "dem":
        return None
    several = result.params.engine == '1d' or params.engine in ("dem", "toy")
    note = "x" if preset.values["engine"].value not in ["1d"] else "y"
    if description.name == "toy" or params.engine_keys.name == "dem":
        pass
    if kind == "dem":
        pass
    match params.engine:
        case "other":
            pass
    match kind:
        case "1d":
            pass
    return {"1d": 1, "dem": 2}[engine]
"""
ENGINE_BRANCHES_ALLOWED = """
def allowed(params, result, description, engine):
    built = DemEngine(params.replace(engine="dem"))
    several = params.engine_keys.several_balls and description.contact_step_guard
    same = params.engine == result.params.engine
    solver = params.solver == "averaged" and params.thermal_model != "paper"
    text = f"engine = {params.engine!r} is not 'dem'"
    known = params.engine in ENGINE_KEYS
    return sm.default_parameters(engine="1d"), {"1d": 1}.get(name)
"""


def test_the_engine_name_check_sees_every_way_of_branching_on_a_name():
    found = engine_name_branches(ENGINE_BRANCHES_SAMPLE)
    assert [line.split(":")[0] for line in found] == [f"line {n}" for n in (3, 5, 5, 6, 7, 7, 9, 11, 14, 17)], found
    assert "line 3: params.engine != 'dem'" in found
    assert engine_name_branches(ENGINE_BRANCHES_ALLOWED) == []


def test_no_module_above_the_engines_branches_on_an_engine_name():
    """solvers/impact.py builds the 'dem' engine for a lone impact (an explicit construction, docs/ARCHITECTURE.md);
    whether a run's restitution is guarded is its engine's declaration (``contact_step_guard``), not its name."""
    found = {
        name: branches
        for name, path in MODULES.items()
        if not name.startswith(ENGINES_PACKAGE) and (branches := engine_name_branches(path.read_text(encoding="utf-8")))
    }
    assert found == {}
