"""Shared test fixtures and the robustness-sweep case counter."""

import collections
import os

# Single-threaded BLAS, for bit-identical results (and 10x faster for
# the small problems of this suite on a shared 2-core machine). Set before numpy loads.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import matplotlib  # noqa: E402

matplotlib.use("Agg")

#: command -> number of robustness cases tried (tests/test_robustness.py fills it)
ROBUSTNESS_CASES: collections.Counter = collections.Counter()


def pytest_terminal_summary(terminalreporter):
    if ROBUSTNESS_CASES:
        terminalreporter.section("robustness sweep: cases tried per reader / command")
        for name, n in sorted(ROBUSTNESS_CASES.items()):
            terminalreporter.write_line(f"{name:40s} {n:6d}")
