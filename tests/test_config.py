"""Config settings: bounds, choices and to_dict from the fields' metadata."""

from dataclasses import dataclass

import pytest

from inertialab.config import Config, setting
from inertialab.errors import InputError


@dataclass(frozen=True)
class C(Config):
    n: int = setting(3, help="a count", lo=1, hi=10)
    x: float | None = setting(None, help="a level", unit="ug", lo=0.0)
    mode: str = setting("a", help="a | b", choices=("a", "b"), flag="the-mode")
    hidden: bool = setting(False, help="off the command line", cli=False)


@pytest.mark.parametrize("kw, match", [
    (dict(n=0), r"argument 'n' must be from 1 to 10, got 0"),
    (dict(n=11), "from 1 to 10"),
    (dict(x=float("nan")), r"argument 'x' must be >= 0, got nan"),
    (dict(x=-1e-9), ">= 0"),
    (dict(x=float("inf")), ">= 0"),
    (dict(n="3"), None),
    (dict(n="three"), "must be a number"),
    (dict(mode="c"), r"argument 'mode' must be one of a, b, got 'c'"),
])
def test_validate(kw, match):
    if match is None:
        C(**kw).validate()
        return
    with pytest.raises(InputError, match=match):
        C(**kw).validate()


def test_fields_metadata_and_to_dict():
    f = {fl.name: m for fl, m in C.fields()}
    assert f["n"]["flag"] == "n" and f["mode"]["flag"] == "the-mode" and not f["hidden"]["cli"]
    assert f["x"]["unit"] == "ug" and f["n"]["lo"] == 1 and f["n"]["hi"] == 10
    assert C(x=2.5).validate().to_dict() == {"n": 3, "x": 2.5, "mode": "a", "hidden": False}
