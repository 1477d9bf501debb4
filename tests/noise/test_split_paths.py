"""noise/ cut into subpackages by meaning: the face of inertialab.noise keeps its
names (each the object of its new home), every old flat module path still imports (a
deprecated alias, tests/export/test_old_paths.py), and noise.terms / noise.gmwm, which were
modules and are now packages, still give the old module's names with a warning."""

import importlib
import warnings

import pytest

import inertialab.noise as noise

#: the face of inertialab.noise before the split (it must not change)
FACE = ['oadev', 'adev', 'mdev', 'tdev', 'hdev', 'ohdev', 'totdev', 'deviation', 'DeviationResult', 'tau_grid', 'mtotdev', 'ttotdev', 'htotdev', 'theo1', 'theobr', 'theoh', 'mtie', 'tierms', 'fit_noise_terms', 'NoiseTerms', 'NoiseTerm', 'STATISTICS', 'Statistic', 'compute', 'gap_deviation', 'fit_gmwm', 'robotics_values', 'k_bound', 'detect_static_intervals']
#: old flat modules -> their new homes
MOVED = {'inertialab.noise.allan': 'inertialab.noise.statistics.allan', 'inertialab.noise.allan_dask': 'inertialab.noise.statistics.allan_dask', 'inertialab.noise.drift_prediction': 'inertialab.noise.terms.drift_prediction', 'inertialab.noise.edf': 'inertialab.noise.statistics.edf', 'inertialab.noise.edf_clock': 'inertialab.noise.statistics.edf_clock', 'inertialab.noise.emd': 'inertialab.noise.spectral.emd', 'inertialab.noise.family': 'inertialab.noise.statistics.family', 'inertialab.noise.gaps': 'inertialab.noise.statistics.gaps', 'inertialab.noise.identify': 'inertialab.noise.statistics.identify', 'inertialab.noise.imu_result': 'inertialab.noise.terms.imu_result', 'inertialab.noise.information': 'inertialab.noise.terms.information', 'inertialab.noise.lines': 'inertialab.noise.spectral.lines', 'inertialab.noise.pooled': 'inertialab.noise.terms.pooled', 'inertialab.noise.registry': 'inertialab.noise.statistics.registry', 'inertialab.noise.robotics': 'inertialab.noise.terms.robotics', 'inertialab.noise.spectra': 'inertialab.noise.spectral.spectra', 'inertialab.noise.static_intervals': 'inertialab.noise.segments.static_intervals', 'inertialab.noise.stationarity': 'inertialab.noise.segments.stationarity', 'inertialab.noise.theo': 'inertialab.noise.statistics.theo', 'inertialab.noise.tie': 'inertialab.noise.statistics.tie', 'inertialab.noise.total': 'inertialab.noise.statistics.total', 'inertialab.noise.warmup': 'inertialab.noise.segments.warmup', 'inertialab.noise.wavelet': 'inertialab.noise.spectral.wavelet'}
#: a few names of the old modules noise.terms and noise.gmwm outside the new faces
LEGACY = {'terms': ['BI_FACTOR', 'CONFIDENCE', 'EDF_MIN'], 'gmwm': ['GmwmFit', 'Process', 'WaveletVariance']}


def test_the_face_of_noise_is_unchanged():
    assert list(noise.__all__) == FACE
    for name in FACE:
        assert getattr(noise, name) is not None, name


@pytest.mark.parametrize("sub", ['gmwm', 'segments', 'spectral', 'statistics', 'terms'])
def test_each_subpackage_face_resolves_without_warning(sub):
    pkg = importlib.import_module(f"inertialab.noise.{sub}")
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        for name in pkg.__all__:
            assert getattr(pkg, name) is getattr(noise, name), name


@pytest.mark.parametrize("old", sorted(MOVED))
def test_an_old_module_path_is_its_new_module(old):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        assert importlib.import_module(old) is importlib.import_module(MOVED[old])


@pytest.mark.parametrize("sub,name", [(s, n) for s in sorted(LEGACY) for n in LEGACY[s]])
def test_an_old_module_name_of_a_new_package_warns(sub, name):
    pkg = importlib.import_module(f"inertialab.noise.{sub}")
    fit = importlib.import_module(f"inertialab.noise.{sub}.fit")
    with pytest.warns(DeprecationWarning, match=f"inertialab.noise.{sub}.{name}"):
        value = getattr(pkg, name)
    assert value is getattr(fit, name)
    assert not hasattr(pkg, "no_such_name")
