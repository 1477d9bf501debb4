"""DESIGN.md's layer order: imports point down only (read with ast)."""

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src" / "inertialab"

# rank: a module may import only modules of lower or equal rank (same package), with the
# exceptions listed below.
RANK = {
    "units": 0, "errors": 0, "seeding": 0, "__init__": 0, "jsonable": 0, "_blas": 0,
    "progress": 0, "estimator": 0,
    "io": 1,
    "metrics": 2, "regress": 2, "noise": 2,
    "learn": 3, "optim": 3,
    "sensors": 4,
    "sim": 5, "calib": 5,
    "workflows": 6, "studies": 7,
    "report": 8,
    "cli": 9, "__main__": 9,
}
# method packages that must not import each other (DESIGN.md: "learn and optim may import
# regress; all may import metrics; nothing else crosses")
METHODS = {"noise", "learn", "optim", "regress"}
ALLOWED_CROSS = {("learn", "regress"), ("optim", "regress")}
# the one upward reference: the model-file loader's lazy allow-list (strings, not imports)


def _layer(modname: str) -> str:
    parts = modname.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _imports(path: Path, modname: str):
    tree = ast.parse(path.read_text(), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield a.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = modname.split(".")[: -node.level]
                yield ".".join(base + ([node.module] if node.module else []))
            elif node.module:
                yield node.module


def test_imports_point_down_only():
    bad = []
    for path in SRC.rglob("*.py"):
        rel = path.relative_to(SRC.parent).with_suffix("")
        modname = ".".join(rel.parts)
        src_layer = _layer(modname)
        if src_layer == "__init__" and path.name == "__init__.py" and path.parent == SRC:
            src_layer = "__init__"
        for imp in _imports(path, modname):
            if not imp.startswith("inertialab"):
                continue
            dst = _layer(imp)
            if dst == src_layer:
                continue
            if src_layer not in RANK or dst not in RANK:
                bad.append(f"{modname} -> {imp} (unknown layer)")
                continue
            if src_layer in METHODS and dst in METHODS and (src_layer, dst) not in ALLOWED_CROSS:
                bad.append(f"{modname} -> {imp} (method packages do not cross)")
            elif RANK[dst] > RANK[src_layer]:
                bad.append(f"{modname} -> {imp} (points up)")
    assert not bad, "layer violations:\n" + "\n".join(bad)


def test_workflows_never_import_matplotlib_and_methods_never_print():
    offenders = []
    for path in SRC.rglob("*.py"):
        rel = path.relative_to(SRC)
        top = rel.parts[0]
        text = path.read_text()
        if top in ("workflows", "sim", "sensors", "noise", "learn", "optim", "regress", "io") and (
                "import matplotlib" in text or "from matplotlib" in text):
            offenders.append(f"{rel}: imports matplotlib")
        if top in ("noise", "learn", "optim", "regress", "sensors") and "print(" in text:
            offenders.append(f"{rel}: prints")
    assert not offenders, "\n".join(offenders)
