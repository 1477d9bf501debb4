"""The package's source as syntax trees, each file parsed once per test process.

The tests that read the code as data (the floors, one home per concept, the faces, the
estimator list) walk every module of ``src/inertialab``; parsing them all takes about a
second of CPU, so :func:`parsed` keeps each tree. The trees are shared: read them, never
change them.
"""

import ast
import functools
from pathlib import Path


@functools.cache
def parsed(path: Path) -> ast.Module:
    """The syntax tree of the Python file at ``path`` (parsed on first use, then kept)."""
    return ast.parse(Path(path).read_text(), filename=str(path))
