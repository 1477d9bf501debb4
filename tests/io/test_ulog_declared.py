"""A PX4 ULog's headers declare the shape of every message: formats nested in formats,
arrays of up to 65 535 elements, any number of subscriptions. pyulog flattens each
subscribed format into one Python object per scalar field before reading any data, so
a 200-byte log can declare billions of objects. The reader checks the declarations
first (:data:`inertialab.io.formats.ulog.MAX_FIELDS`)."""

from __future__ import annotations

import time

import pytest
from tests.fuzz.second_round import ULOG_COUNT_BOMB, ULOG_NESTED_BOMB, ulog_bytes

from inertialab.errors import InputError

pytest.importorskip("pyulog")

from inertialab.io.formats import ulog  # noqa: E402


def _read(tmp_path, formats, subs):
    f = tmp_path / "x.ulg"
    f.write_bytes(ulog_bytes(formats, subs))
    t0 = time.perf_counter()
    try:
        ulog.read_ulog(f)
    finally:
        wall = time.perf_counter() - t0
    return wall


@pytest.mark.parametrize("bomb", [ULOG_NESTED_BOMB, ULOG_COUNT_BOMB], ids=["nested", "count"])
def test_declared_fields_are_refused_before_pyulog_builds_them(tmp_path, bomb):
    with pytest.raises(InputError, match=r"x\.ulg: .*more than 200000 fields") as exc:
        _read(tmp_path, *bomb)
    assert "\n" not in str(exc.value)


def test_the_bound_counts_fields_exactly(tmp_path):
    """3 x 60 001 fields (timestamp + 60 000 floats) pass the bound: the log is read and
    found to hold no data; 4 x 60 001 do not."""
    fmt = ["wide:uint64_t timestamp;float[60000] x;"]
    assert 3 * 60_001 <= ulog.MAX_FIELDS < 4 * 60_001
    with pytest.raises(InputError, match="no 'sensor_combined' messages"):
        _read(tmp_path, fmt, ["wide"] * 3)
    with pytest.raises(InputError, match="more than 200000 fields"):
        _read(tmp_path, fmt, ["wide"] * 4)


def test_nested_fields_multiply(tmp_path):
    """A format of 10 nested types of 10 000 floats each is 100 001 fields: twice is
    over the bound, once is not."""
    fmt = ["pair:uint64_t timestamp;inner[10] b;", "inner:float[10000] x;"]
    assert ulog._flat_fields("pair", {f.split(":")[0]: _Fmt(f) for f in fmt}, {},
                             {"float", "uint64_t"}) == 100_001
    with pytest.raises(InputError, match="no 'sensor_combined' messages"):
        _read(tmp_path, fmt, ["pair"])
    with pytest.raises(InputError, match="more than 200000 fields"):
        _read(tmp_path, fmt, ["pair", "pair"])


class _Fmt:
    def __init__(self, text):
        import re

        self.fields = []
        for part in filter(None, text.split(":")[1].split(";")):
            typ, name = part.split()
            m = re.match(r"(\w+)\[(\d+)\]", typ)
            self.fields.append((m[1], int(m[2]), name) if m else (typ, 0, name))


@pytest.mark.parametrize("formats,why", [
    (["sensor_combined:uint64_t timestamp;sensor_combined again;"], "contains itself"),
    ([f"t{i}:uint64_t timestamp;t{i + 1} n;" for i in range(40)] + ["t40:float x;"],
     "nested more than 32 deep"),
])
def test_cyclic_or_deep_formats_are_one_line(tmp_path, formats, why):
    with pytest.raises(InputError, match=why):
        _read(tmp_path, formats, [formats[0].split(":")[0]])
