"""Shared test fixtures and the robustness-sweep case counter."""

import collections

import matplotlib

matplotlib.use("Agg")

#: command -> number of robustness cases tried (tests/test_robustness.py fills it)
ROBUSTNESS_CASES: collections.Counter = collections.Counter()


def pytest_terminal_summary(terminalreporter):
    if ROBUSTNESS_CASES:
        terminalreporter.section("robustness sweep: cases tried per reader / command")
        for name, n in sorted(ROBUSTNESS_CASES.items()):
            terminalreporter.write_line(f"{name:40s} {n:6d}")
