"""The YAML every exporter writes: through a serialiser (:func:`dump_yaml`, PyYAML's
safe dumper: a value can never add a key or break the document), with comments made
safe (:func:`comment_lines`), exact float spelling (:func:`yaml_number`), one-line
mappings (:class:`Flow`) and checked ROS topic names (:func:`check_topic`).
"""

from __future__ import annotations

import math
import re

from inertialab.errors import InputError

__all__ = ["Flow", "check_topic", "comment_lines", "dump_yaml", "yaml_number"]


def yaml_number(x: float) -> str:
    """A float as YAML 1.1 and 1.2 both read back exactly: the shortest round-trip
    repr with a dot in the mantissa (PyYAML reads ``1e-05`` as a string).

    Examples
    --------
    >>> yaml_number(1e-05), yaml_number(200), yaml_number(0.1)
    ('1.0e-05', '200.0', '0.1')
    """
    s = repr(float(x))
    if "e" in s or "E" in s:
        mant, exp = s.lower().split("e")
        if "." not in mant:
            mant += ".0"
        s = f"{mant}e{exp}"
    elif "." not in s and "inf" not in s and "nan" not in s:
        s += ".0"
    return s


class Flow(dict):
    """A mapping written in YAML flow style (``{a: 1, b: 2}``) on one line."""


def _dumper():
    import yaml

    class Dumper(yaml.SafeDumper):
        pass

    def flow_map(dumper, data):
        return dumper.represent_mapping("tag:yaml.org,2002:map", data.items(), flow_style=True)

    def seq(dumper, data):  # rows of numbers on one line each, nested lists in block style
        flat = all(not isinstance(v, (list, tuple, dict)) for v in data)
        return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flat)

    def num(dumper, data):
        if not math.isfinite(data):
            return dumper.represent_scalar("tag:yaml.org,2002:null", "null")
        return dumper.represent_scalar("tag:yaml.org,2002:float", yaml_number(data))

    Dumper.add_representer(Flow, flow_map)
    Dumper.add_representer(list, seq)
    Dumper.add_representer(tuple, seq)
    Dumper.add_representer(float, num)
    return Dumper


def dump_yaml(data: dict, *, comments=(), directive: str | None = None) -> str:
    """``data`` as YAML through PyYAML's safe dumper (block style, keys in the given
    order, NaN as ``null``), after ``directive`` (OpenCV's ``%YAML:1.0``) and the
    ``comments`` lines (each made a comment by :func:`comment_lines`)."""
    try:
        import yaml
    except ImportError:  # pragma: no cover - PyYAML is a dependency
        raise InputError("writing YAML needs PyYAML: pip install pyyaml") from None
    head = [directive] if directive else []
    head += comment_lines(comments)
    body = yaml.dump(data, Dumper=_dumper(), sort_keys=False, default_flow_style=False,
                     allow_unicode=False, width=1 << 16)
    return "\n".join(head + [body.rstrip("\n")]) + "\n"


def comment_lines(lines, width: int = 88) -> list[str]:
    """``# ...`` lines, wrapped at ``width``: every line break inside a text starts a new
    comment line, so data placed in a comment (a method name, a unit id) cannot start a
    YAML line."""
    import textwrap

    out = []
    for text in lines:
        for part in str(text).splitlines() or [""]:
            wrapped = textwrap.wrap(part, width - 2, break_long_words=False,
                                    break_on_hyphens=False) or [""]
            out += [("# " + w).rstrip() for w in wrapped]
    return out


#: A ROS graph resource name (ROS wiki "Names"): '/', '~' or a letter first, then
#: letters, digits, '_' and '/'.
_ROS_NAME = re.compile(r"[~/A-Za-z][A-Za-z0-9_/]*")


def check_topic(topic: str, what: str = "rostopic") -> str:
    """``topic`` when it is a valid ROS name; else one-line InputError naming ``what``.

    Examples
    --------
    >>> check_topic("/imu0")
    '/imu0'
    >>> check_topic("imu0; rm -rf")
    Traceback (most recent call last):
    ...
    inertialab.errors.InputError: argument 'rostopic' must be a ROS topic name (letters, digits, _ and /), got 'imu0; rm -rf'
    """
    t = str(topic)
    if not _ROS_NAME.fullmatch(t) or len(t) > 256:
        raise InputError(f"argument '{what}' must be a ROS topic name (letters, digits, _ and "
                         f"/), got {t[:60]!r}")
    return t
