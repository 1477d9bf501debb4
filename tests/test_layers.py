"""The floors of docs/architecture.md, read with ast: imports point down only, no import
circles, no project module imported by string, sim/ only above workflows, no CLI flag
names below cli/, cli/ imports no method or model floor, matplotlib only in report/,
methods never print, no function above 100 lines. Modules are cut by meaning, not by a
line count: there is no ceiling on a module's or a floor's length."""

import ast
import re
from pathlib import Path

from tests.source_trees import parsed

SRC = Path(__file__).resolve().parent.parent / "src" / "inertialab"

# rank: a module may import only modules of lower rank, or of its own package.
RANK = {
    "units": 0, "errors": 0, "seeding": 0, "__init__": 0, "jsonable": 0, "blas": 0,
    "progress": 0, "estimator": 0, "config": 0, "limits": 0, "signals": 0, "result": 0,
    "io": 1,
    "metrics": 2, "regress": 2, "noise": 2,
    "learn": 3, "optim": 3,
    "sensors": 4,
    "sim": 5, "calib": 5,
    "export": 6,
    "workflows": 7,
    "studies": 8,
    "report": 9,
    "cli": 10, "__main__": 10,
}
#: Deprecated aliases kept for one release at an old path below their new home: each
#: module under the old path imports only its new home (which is why it may point up),
#: defines no function or class and warns (``test_deprecated_aliases_only_point_home``).
ALIASES = {"inertialab.io.exporters": "inertialab.export",
           "inertialab.io.preflight": "inertialab.workflows.preflight",
           "inertialab.noise.allan": "inertialab.noise.statistics",
           "inertialab.noise.allan_dask": "inertialab.noise.statistics",
           "inertialab.noise.drift_prediction": "inertialab.noise.terms",
           "inertialab.noise.edf": "inertialab.noise.statistics",
           "inertialab.noise.edf_clock": "inertialab.noise.statistics",
           "inertialab.noise.emd": "inertialab.noise.spectral",
           "inertialab.noise.family": "inertialab.noise.statistics",
           "inertialab.noise.gaps": "inertialab.noise.statistics",
           "inertialab.noise.identify": "inertialab.noise.statistics",
           "inertialab.noise.imu_result": "inertialab.noise.terms",
           "inertialab.noise.information": "inertialab.noise.terms",
           "inertialab.noise.lines": "inertialab.noise.spectral",
           "inertialab.noise.pooled": "inertialab.noise.terms",
           "inertialab.noise.registry": "inertialab.noise.statistics",
           "inertialab.noise.robotics": "inertialab.noise.terms",
           "inertialab.noise.spectra": "inertialab.noise.spectral",
           "inertialab.noise.static_intervals": "inertialab.noise.segments",
           "inertialab.noise.stationarity": "inertialab.noise.segments",
           "inertialab.noise.theo": "inertialab.noise.statistics",
           "inertialab.noise.tie": "inertialab.noise.statistics",
           "inertialab.noise.total": "inertialab.noise.statistics",
           "inertialab.noise.warmup": "inertialab.noise.segments",
           "inertialab.noise.wavelet": "inertialab.noise.spectral"}


def _alias_home(modname: str):
    return next((home for old, home in ALIASES.items()
                 if modname == old or modname.startswith(old + ".")), None)
# method packages that must not import each other ("learn and optim may import regress;
# all may import metrics; nothing else crosses"); calib and sim do not cross.
METHODS = {"noise", "learn", "optim", "regress"}
ALLOWED_CROSS = {("learn", "regress"), ("optim", "regress")}
NO_CROSS = {("calib", "sim"), ("sim", "calib")}
# floors that may import sim/ (studies/ and cli/ only)
SIM_USERS = {"sim", "studies", "cli", "__main__"}


def _modules():
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        yield path, ".".join(parts)


def _layer(modname: str) -> str:
    parts = modname.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _imports(path: Path, modname: str, *, is_pkg: bool, submodules: bool = False):
    tree = parsed(path)
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield a.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = modname.split(".")
                base = base[: len(base) - node.level + (1 if is_pkg else 0)]
                yield ".".join(base + ([node.module] if node.module else []))
            elif node.module:
                yield node.module
                if submodules:  # `from pkg import module` (for the circle graph)
                    for a in node.names:
                        yield f"{node.module}.{a.name}"


def _graph():
    mods = dict((name, path) for path, name in _modules())
    graph = {}
    for name, path in mods.items():
        deps = set()
        for imp in _imports(path, name, is_pkg=path.name == "__init__.py", submodules=True):
            if imp.startswith("inertialab") and imp in mods and imp != name:
                deps.add(imp)
        graph[name] = deps
    return graph


def test_imports_point_down_only():
    bad = []
    for path, modname in _modules():
        src_layer = _layer(modname)
        home = _alias_home(modname)
        for imp in _imports(path, modname, is_pkg=path.name == "__init__.py"):
            if not imp.startswith("inertialab"):
                continue
            if home and (imp == home or imp.startswith(home + ".")):
                continue
            dst = _layer(imp)
            if dst == src_layer:
                continue
            if src_layer not in RANK or dst not in RANK:
                bad.append(f"{modname} -> {imp} (unknown layer)")
                continue
            if src_layer in METHODS and dst in METHODS and (src_layer, dst) not in ALLOWED_CROSS:
                bad.append(f"{modname} -> {imp} (method packages do not cross)")
            elif (src_layer, dst) in NO_CROSS:
                bad.append(f"{modname} -> {imp} ({src_layer} and {dst} do not cross)")
            elif dst == "sim" and src_layer not in SIM_USERS:
                bad.append(f"{modname} -> {imp} (only studies/ and cli/ import sim/)")
            elif RANK[dst] > RANK[src_layer]:
                bad.append(f"{modname} -> {imp} (points up)")
    assert not bad, "layer violations:\n" + "\n".join(sorted(set(bad)))


def test_deprecated_aliases_only_point_home():
    bad = []
    for path, modname in _modules():
        home = _alias_home(modname)
        if home is None:
            continue
        tree = ast.parse(path.read_text())
        defines = [n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))]
        away = [i for i in _imports(path, modname, is_pkg=path.name == "__init__.py")
                if i.startswith("inertialab") and not (i == home or i.startswith(home + "."))]
        if defines or away or "DeprecationWarning" not in path.read_text():
            bad.append(f"{modname}: defines {defines}, imports {away}")
    assert not bad, "\n".join(bad)
    assert all(any(_alias_home(m) for _, m in _modules() if m.startswith(old)) for old in ALIASES)


def test_no_import_circles():
    graph = _graph()
    index, low, on_stack, stack, cycles = {}, {}, set(), [], []
    counter = [0]

    def strong(v):  # Tarjan's strongly connected components
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            strong(v)
    # a package __init__ re-exporting its own modules is not a circle of modules
    real = [c for c in cycles
            if not all(any(o.startswith(m + ".") for o in c) or
                       any(m.startswith(o + ".") for o in c) for m in c)]
    assert not real, "import circles:\n" + "\n".join(" <-> ".join(c) for c in real)


_FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9]*(?:-[a-z0-9]+)*")


def _message_strings(tree):
    """String constants that are not docstrings (messages, f-string parts)."""
    docs = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            body = getattr(node, "body", [])
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                docs.add(id(body[0].value))
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
            yield node


def test_no_cli_flag_names_below_cli():
    bad = []
    for path, modname in _modules():
        if _layer(modname) in ("cli", "__main__"):
            continue
        tree = parsed(path)
        for node in _message_strings(tree):
            for m in _FLAG.findall(node.value):
                bad.append(f"{modname}:{node.lineno}: {m}")
    assert not bad, ("flag names below cli/ (name the argument; cli/options.flagged maps it):\n"
                     + "\n".join(bad))


def test_workflows_never_import_matplotlib_and_methods_never_print():
    offenders = []
    for path in SRC.rglob("*.py"):
        rel = path.relative_to(SRC)
        top = rel.parts[0]
        text = path.read_text()
        if top not in ("report", "cli") and ("import matplotlib" in text
                                              or "from matplotlib" in text):
            offenders.append(f"{rel}: imports matplotlib")
        if top in ("noise", "learn", "optim", "regress", "sensors", "calib") and "print(" in text:
            offenders.append(f"{rel}: prints")
    assert not offenders, "\n".join(offenders)



def _string_imports(tree):
    """Calls that import a module named by a string (``importlib.import_module(...)``,
    ``__import__(...)``) whose name is a project module."""
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call) or not node.args:
            continue
        f = node.func
        name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
        if name not in ("import_module", "__import__"):
            continue
        arg = node.args[0]
        text = arg.value if isinstance(arg, ast.Constant) else ast.unparse(arg)
        if "inertialab" in str(text):
            yield node.lineno, str(text)


def test_no_project_module_imported_by_string():
    """Registries and discovery import their modules explicitly, so this test's import
    graph sees every edge (third-party extras may still be imported by name)."""
    bad = [f"{modname}:{line}: {text}" for path, modname in _modules()
           for line, text in _string_imports(parsed(path))]
    assert not bad, "project modules imported by string:\n" + "\n".join(bad)


# The command line parses, runs one workflow call and writes; it imports no method or
# model floor.
CLI_FORBIDDEN = {"calib", "noise", "sensors", "learn", "optim", "regress"}
#: Functions above 100 lines, with their length as a ceiling (none left; nothing may
#: join it).
LONG_FUNCTIONS: dict[str, int] = {}
MAX_FUNCTION_LINES = 100


def test_cli_imports_no_method_or_model_floor():
    bad = []
    for path, modname in _modules():
        if _layer(modname) != "cli":
            continue
        for imp in _imports(path, modname, is_pkg=path.name == "__init__.py"):
            if imp.startswith("inertialab.") and _layer(imp) in CLI_FORBIDDEN:
                bad.append(f"{modname} -> {imp}")
    assert not bad, "cli/ imports a method or model floor:\n" + "\n".join(sorted(set(bad)))


def _docstring_lines(node) -> int:
    """Lines of a function's docstring (its Examples included), which the rule does not
    count: the rule bounds the code a reader follows, not the documentation."""
    body = node.body
    if (body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
            and isinstance(body[0].value.value, str)):
        return body[0].end_lineno - body[0].lineno + 1
    return 0


def test_no_function_above_100_lines():
    bad = []
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        for node in ast.walk(parsed(path)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1 - _docstring_lines(node)
                limit = LONG_FUNCTIONS.get(f"{rel}:{node.name}", MAX_FUNCTION_LINES)
                if n > limit:
                    bad.append(f"{rel}:{node.name}: {n} lines (at most {limit})")
    assert not bad, "functions too long:\n" + "\n".join(bad)



def test_cli_reads_inputs_only_through_the_runner():
    """In cli/, only runner.py reads a record or a model file (read_record, load_model)
    or parses JSON; the command modules ask the runner (main.py reads the --config TOML
    of a run, not an input). No command module reads a table itself (pandas/numpy
    readers) or calls a reader by attribute (``io.read_record``)."""
    bad = []
    for path in sorted((SRC / "cli").glob("*.py")):
        if path.name not in ("runner.py", "main.py"):
            bad += _cli_readings(path.name, parsed(path))
    assert not bad, bad


_CLI_READERS = {"read_record", "load_model", "read_envelope", "loads", "load", "read_csv",
                "read_parquet", "read_clock", "read_imu_thermal_log", "read_table", "read_r"}


def _cli_readings(name: str, tree) -> list[str]:
    bad = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and \
                node.module.startswith("inertialab.") and node.module != "inertialab.cli.runner":
            bad += [f"{name}: {node.module}.{a.name}" for a in node.names
                    if a.name in _CLI_READERS]
        if isinstance(node, ast.Attribute) and node.attr in ("loads", "load") and \
                getattr(node.value, "id", "") == "json":
            bad.append(f"{name}:{node.lineno}: json.{node.attr}")
        elif isinstance(node, ast.Attribute) and node.attr in _CLI_READERS - {"loads", "load"}:
            bad.append(f"{name}:{node.lineno}: .{node.attr}")
    return bad


def test_the_cli_rule_sees_a_reading():
    """The rule above is not blind: a command module reading a record through io, a
    table through pandas, or parsing JSON, is caught."""
    code = ("from inertialab.io import read_record\nimport json, pandas as pd\n"
            "def f(p):\n    return json.loads(p), pd.read_csv(p)\n")
    found = _cli_readings("x.py", ast.parse(code))
    assert sorted(found) == ["x.py: inertialab.io.read_record", "x.py:4: .read_csv",
                             "x.py:4: json.loads"]


#: ``workflows/*_run.py`` modules that still hold their commands (not yet merged into
#: their study's module).
_RUN_MODULES_NOT_MERGED: set[str] = set()


def test_one_workflow_module_per_study():
    """A ``workflows/<study>_run.py`` is a deprecated alias: it defines no function or
    class, imports its names from ``workflows/<study>.py`` and warns on import."""
    bad = []
    for path in sorted((SRC / "workflows").glob("*_run.py")):
        if path.name in _RUN_MODULES_NOT_MERGED:
            continue
        tree = parsed(path)
        study = path.name.removesuffix("_run.py")
        defines = [n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))]
        sources = {n.module for n in tree.body if isinstance(n, ast.ImportFrom)}
        warns = "DeprecationWarning" in path.read_text()
        if defines or f"inertialab.workflows.{study}" not in sources or not warns:
            bad.append(f"{path.name}: defines {defines}, imports {sorted(sources)}, "
                       f"warns {warns}")
    assert not bad, "\n".join(bad)
    assert all((SRC / "workflows" / n).exists() for n in _RUN_MODULES_NOT_MERGED)
