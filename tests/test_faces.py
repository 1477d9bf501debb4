"""The packages' public faces: every package declares ``__all__``, every name in it
resolves, every public function and class in a face carries an Examples section that
``pytest --doctest-modules`` (the test command's default over src/inertialab) collects
and runs from the module defining it, and no module imports another package's private
name."""

import ast
import doctest
import functools
import importlib
import inspect
from pathlib import Path

from tests.source_trees import parsed

SRC = Path(__file__).resolve().parent.parent / "src" / "inertialab"


def _packages() -> list[str]:
    return sorted("inertialab" + "".join("." + p for p in init.parent.relative_to(SRC).parts)
                  for init in SRC.rglob("__init__.py"))


def _all_of(package: str):
    path = SRC.joinpath(*package.split(".")[1:], "__init__.py")
    for node in parsed(path).body:
        targets = node.targets if isinstance(node, ast.Assign) else (
            [node.target] if isinstance(node, ast.AnnAssign) else [])
        if any(getattr(t, "id", "") == "__all__" for t in targets):
            return node
    return None


def test_every_package_declares_all():
    missing = [p for p in _packages() if _all_of(p) is None]
    assert not missing, f"packages without __all__: {missing}"


def _face_objects():
    for package in _packages():
        mod = importlib.import_module(package)
        for name in mod.__all__:
            yield package, name, getattr(mod, name)


def test_every_name_of_a_face_resolves():
    assert sum(1 for _ in _face_objects()) > 50


@functools.cache
def _collected_examples(module_name: str) -> set[str]:
    """Names of the docstrings with examples that doctest collects from a module, as
    ``pytest --doctest-modules`` does."""
    module = importlib.import_module(module_name)
    return {t.name for t in doctest.DocTestFinder().find(module) if t.examples}


def _lacks_example(obj) -> bool:
    doc = inspect.getdoc(obj) or ""
    if "Examples" not in doc or ">>>" not in doc:
        return True
    return f"{obj.__module__}.{obj.__qualname__}" not in _collected_examples(obj.__module__)


def test_public_functions_and_classes_of_the_faces_have_examples():
    lacking = {f"{package}.{name}" for package, name, obj in _face_objects()
               if (inspect.isfunction(obj) or inspect.isclass(obj)) and _lacks_example(obj)}
    assert not lacking, f"public names without a doctested Examples section: {sorted(lacking)}"


def _private_imports():
    for path in sorted(SRC.rglob("*.py")):
        parts = list(path.relative_to(SRC.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        here = parts[1] if len(parts) > 1 else ""
        for node in ast.walk(parsed(path)):
            if not (isinstance(node, ast.ImportFrom) and node.module
                    and node.module.startswith("inertialab.")):
                continue
            mods = node.module.split(".")
            there = mods[1]
            private_module = any(m.startswith("_") for m in mods[1:])
            for a in node.names:
                private = a.name.startswith("_") and not a.name.startswith("__")
                if (private or private_module) and there != here:
                    yield f"{'.'.join(parts)} -> {node.module}.{a.name}"


def test_no_cross_package_private_imports():
    found = sorted(_private_imports())
    assert not found, f"imports of another package's private names: {found}"

