"""Shared test fixtures, the robustness-sweep case counter and the number of workers.

``pytest`` alone (the whole suite) runs on one worker process per available core, at most
:data:`MAX_WORKERS` (pytest-xdist, in the ``test`` extra; ``-n auto --dist loadfile`` in
pyproject.toml's addopts); a run that names paths runs in this one process unless it asks
for workers (``-n 2``). Each test file runs whole on one worker, so a module fixture is
built once, and a session fixture at most once per worker. Every test is seeded, so the
outcome does not depend on the number of workers or on which worker runs a file.
"""

import collections
import os

# Single-threaded BLAS, for bit-identical results (and 10x faster for
# the small problems of this suite on a shared 2-core machine). Set before numpy loads.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import matplotlib  # noqa: E402
import pytest  # noqa: E402

matplotlib.use("Agg")

#: command -> number of robustness cases tried (tests/test_robustness.py fills it)
ROBUSTNESS_CASES: collections.Counter = collections.Counter()

#: The most worker processes the whole suite starts (memory: about 1.2 GB each at peak).
MAX_WORKERS = 4

#: study name -> its StudyResult with the QUICK settings (see :func:`quick_study`)
_QUICK_RESULTS: dict = {}


@pytest.fixture(scope="session")
def quick_study():
    """``quick_study(name)``: the registered study ``name`` run once with its QUICK
    settings, as ``inertialab demo --quick`` runs it (:func:`run_studies`), shared by the
    tests that check a study's numbers, its report section and the report in a browser.
    Treat the result as read-only."""
    from inertialab.studies.demo import run_studies

    def get(name: str):
        if name not in _QUICK_RESULTS:
            _QUICK_RESULTS[name] = run_studies([name], quick=True)[0]
        return _QUICK_RESULTS[name]

    return get


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_auto_num_workers(config):
    """``-n auto``: one worker per available core (at most :data:`MAX_WORKERS`, none on
    one core) for the whole suite; none (this process) for a run that names paths, where
    starting workers costs more than it saves. PYTEST_XDIST_AUTO_NUM_WORKERS overrides."""
    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS"):
        return None  # xdist's own rule reads the variable
    if config.args_source is not pytest.Config.ArgsSource.TESTPATHS:
        return 0
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    n = min(MAX_WORKERS, cores or 1)
    return n if n > 1 else 0


def pytest_sessionfinish(session):
    """On an xdist worker: hand its robustness counts to the controller."""
    workeroutput = getattr(session.config, "workeroutput", None)
    if workeroutput is not None:
        workeroutput["robustness_cases"] = dict(ROBUSTNESS_CASES)


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """On the xdist controller: add a finished worker's robustness counts."""
    ROBUSTNESS_CASES.update(getattr(node, "workeroutput", {}).get("robustness_cases", {}))


def pytest_terminal_summary(terminalreporter):
    if ROBUSTNESS_CASES:
        terminalreporter.section("robustness sweep: cases tried per reader / command")
        for name, n in sorted(ROBUSTNESS_CASES.items()):
            terminalreporter.write_line(f"{name:40s} {n:6d}")
