"""The names that moved keep working from their old import paths for one release, with a
DeprecationWarning on import: ``inertialab.io.exporters`` (and each of its submodules) is
:mod:`inertialab.export`, ``inertialab.io.preflight`` is
:mod:`inertialab.workflows.preflight`,
each flat module of noise/ (``inertialab.noise.allan``) is its module in a subpackage
(:mod:`inertialab.noise.statistics.allan`); the six-axis result imports from the workflow (its
face) and from its home, noise/terms/imu_result.py, as one class."""

import importlib
import sys
import warnings

import pytest

OLD_TO_NEW = {
    "inertialab.io.exporters": "inertialab.export",
    "inertialab.io.exporters.kalibr": "inertialab.export.kalibr",
    "inertialab.io.exporters.openvins": "inertialab.export.openvins",
    "inertialab.io.exporters.imu_utils": "inertialab.export.imu_utils",
    "inertialab.io.exporters.gtsam": "inertialab.export.gtsam",
    "inertialab.io.exporters.ros": "inertialab.export.ros",
    "inertialab.io.exporters.imucal": "inertialab.export.imucal",
    "inertialab.io.exporters.imu_tk": "inertialab.export.imu_tk",
    "inertialab.io.exporters.thermal_c": "inertialab.export.thermal_c",
    "inertialab.io.exporters.thermal_params": "inertialab.export.thermal_params",
    "inertialab.io.exporters.noise": "inertialab.export.noise_params",
    "inertialab.io.exporters._triad": "inertialab.export.triad",
    "inertialab.io.exporters._common": "inertialab.export.yaml_text",
    "inertialab.io.preflight": "inertialab.workflows.preflight",
    "inertialab.noise.allan": "inertialab.noise.statistics.allan",
    "inertialab.noise.allan_dask": "inertialab.noise.statistics.allan_dask",
    "inertialab.noise.drift_prediction": "inertialab.noise.terms.drift_prediction",
    "inertialab.noise.edf": "inertialab.noise.statistics.edf",
    "inertialab.noise.edf_clock": "inertialab.noise.statistics.edf_clock",
    "inertialab.noise.emd": "inertialab.noise.spectral.emd",
    "inertialab.noise.family": "inertialab.noise.statistics.family",
    "inertialab.noise.gaps": "inertialab.noise.statistics.gaps",
    "inertialab.noise.identify": "inertialab.noise.statistics.identify",
    "inertialab.noise.imu_result": "inertialab.noise.terms.imu_result",
    "inertialab.noise.information": "inertialab.noise.terms.information",
    "inertialab.noise.lines": "inertialab.noise.spectral.lines",
    "inertialab.noise.pooled": "inertialab.noise.terms.pooled",
    "inertialab.noise.registry": "inertialab.noise.statistics.registry",
    "inertialab.noise.robotics": "inertialab.noise.terms.robotics",
    "inertialab.noise.spectra": "inertialab.noise.spectral.spectra",
    "inertialab.noise.static_intervals": "inertialab.noise.segments.static_intervals",
    "inertialab.noise.stationarity": "inertialab.noise.segments.stationarity",
    "inertialab.noise.theo": "inertialab.noise.statistics.theo",
    "inertialab.noise.tie": "inertialab.noise.statistics.tie",
    "inertialab.noise.total": "inertialab.noise.statistics.total",
    "inertialab.noise.warmup": "inertialab.noise.segments.warmup",
    "inertialab.noise.wavelet": "inertialab.noise.spectral.wavelet",
}


def _fresh_import(name):
    """Import ``name`` as a first import would (its earlier import forgotten), recording
    the warnings."""
    sys.modules.pop(name, None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mod = importlib.import_module(name)
    return mod, [w for w in caught if issubclass(w.category, DeprecationWarning)]


@pytest.mark.parametrize("old", sorted(OLD_TO_NEW))
def test_an_old_path_warns_and_gives_the_new_names(old):
    new = importlib.import_module(OLD_TO_NEW[old])
    mod, caught = _fresh_import(old)
    assert any(old in str(w.message) and "deprecated" in str(w.message) for w in caught)
    public = [n for n in dir(mod) if not n.startswith("_")]
    assert public
    for name in public:
        if hasattr(new, name):
            assert getattr(mod, name) is getattr(new, name), name


def test_the_old_names_callers_used_still_resolve():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        from inertialab.export import export_noise, targets
        from inertialab.export.noise_params import noise_params
        from inertialab.io.exporters import export_noise as old_export_noise
        from inertialab.io.exporters import targets as old_targets
        from inertialab.io.exporters.noise import noise_params as old_noise_params
        from inertialab.io.preflight import KINDS, preflight, read_for
        from inertialab.workflows import preflight as home
    assert (old_export_noise, old_targets, old_noise_params) == (export_noise, targets,
                                                                  noise_params)
    assert (KINDS, preflight, read_for) == (home.KINDS, home.preflight, home.read_for)


def test_the_six_axis_result_has_one_class_in_two_faces():
    from inertialab.noise.terms import imu_result
    from inertialab.workflows import imu_noise

    assert imu_noise.IMUNoise is imu_result.IMUNoise
    assert imu_noise.AxisNoise is imu_result.AxisNoise
    assert imu_noise.term_text is imu_result.term_text


#: Modules of the package still importing a deprecated path (their owners move them to
#: inertialab.export / inertialab.workflows.preflight). Only shrinks.
DEPRECATED_IMPORTS_LEFT: set[str] = set()


def test_the_package_itself_leaves_the_old_paths():
    import ast
    from pathlib import Path

    src = Path(__file__).resolve().parents[2] / "src" / "inertialab"
    old = ("inertialab.io.exporters", "inertialab.io.preflight",
           *(o for o in OLD_TO_NEW if o.startswith("inertialab.noise.")))
    found = set()
    for path in src.rglob("*.py"):
        rel = path.relative_to(src).as_posix()
        if rel.startswith("io/exporters/") or rel == "io/preflight.py" or \
                f"inertialab.{rel[:-3].replace('/', '.')}" in OLD_TO_NEW:
            continue  # the aliases themselves
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([node.module] + [f"{node.module}.{a.name}" for a in node.names]
                     if isinstance(node, ast.ImportFrom) and node.module else
                     [a.name for a in node.names] if isinstance(node, ast.Import) else [])
            if any(n == o or n.startswith(o + ".") for n in names for o in old):
                found.add(rel)
    assert not found - DEPRECATED_IMPORTS_LEFT, sorted(found - DEPRECATED_IMPORTS_LEFT)
    assert not DEPRECATED_IMPORTS_LEFT - found, (
        f"no longer imports an old path; remove: {sorted(DEPRECATED_IMPORTS_LEFT - found)}")
