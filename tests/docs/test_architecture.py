"""docs/architecture.md is true to the code: every module, file, class and function it
names in backticks exists (dotted names are imported and looked up), and the pages it
links to exist."""

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "architecture.md"
SRC = ROOT / "src" / "inertialab"

_TICK = re.compile(r"`([^`\n]+)`")
_DOTTED = re.compile(r"^inertialab(?:\.\w+)+$")
_PATH = re.compile(r"^[\w./-]+/$|^[\w./-]+\.(?:py|md|json)$")


def _names():
    text = PAGE.read_text()
    out = set()
    for block in re.split(r"```", text)[0::2]:            # outside fenced blocks
        for tok in _TICK.findall(block):
            tok = tok.strip()
            if "<" in tok or " " in tok:
                continue
            if _DOTTED.match(tok) or (_PATH.match(tok) and "/" in tok):
                out.add(tok)
    return sorted(out)


def _resolve(dotted: str):
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ModuleNotFoundError:
            continue
        for attr in parts[i:]:
            obj = getattr(obj, attr)
        return obj
    raise ModuleNotFoundError(dotted)


def test_the_page_names_things():
    names = _names()
    assert sum(bool(_DOTTED.match(n)) for n in names) >= 40
    assert sum(bool(_PATH.match(n)) for n in names) >= 40


@pytest.mark.parametrize("name", _names())
def test_every_named_thing_exists(name):
    if _DOTTED.match(name):
        assert _resolve(name) is not None
        return
    candidates = [SRC / name, ROOT / name, ROOT / "docs" / name]
    assert any(c.exists() for c in candidates), f"{name}: no such file or folder"


def test_linked_pages_exist():
    for target in re.findall(r"\]\(([^)#]+\.md)\)", PAGE.read_text()):
        assert (PAGE.parent / target).is_file(), target


def test_the_study_table_names_existing_modules():
    rows = [r for r in PAGE.read_text().splitlines() if r.startswith("| ") and "`" in r
            and r.count("|") >= 7 and "inertialab " in r]
    assert len(rows) == 6
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        for floor, cell in zip(("calib", "workflows", "studies"), cells[2:5]):
            for name in re.findall(r"`(\w+\.py)`", cell.split("(")[0]):
                assert (SRC / floor / name).is_file(), (floor, name)


def _rules() -> list[str]:
    text = PAGE.read_text()
    section = text[text.index("Rules beside the order"):text.index("## One home per concern")]
    return [b for b in re.split(r"\n- ", section)[1:]]


def test_every_rule_names_the_test_that_keeps_it():
    """Each rule of the page cites ``tests/...py::test_name``, and that test exists."""
    rules = _rules()
    assert len(rules) >= 10
    for rule in rules:
        refs = re.findall(r"`(tests/[\w/]+\.py)::(\w+)`", rule)
        assert refs, f"a rule without its test: {rule[:60]}"
        for path, name in refs:
            text = (ROOT / path).read_text()
            assert re.search(rf"^def {name}\(", text, re.M), f"{path}::{name} does not exist"
