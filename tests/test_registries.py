"""Conformance over everything registered: statistics (noise.statistics.registry), model types
(calib.model_types), file formats (io.formats.registry). Exporters: tests/export/
test_registry.py."""

from pathlib import Path

import numpy as np
import pytest

from inertialab.calib.base import ModelContract
from inertialab.calib.model_types import MODEL_TYPES, TYPES, load_model, save_model
from inertialab.errors import InputError
from inertialab.io.model_schemas import SCHEMAS
from inertialab.noise.statistics import family
from inertialab.noise.statistics import registry as stats

MODELS = Path(__file__).parent / "data" / "models"
RNG = np.random.default_rng(7)
WHITE = RNG.standard_normal(4096)


# ------------------------------------------------------------------ statistics

def test_statistics_are_declared_once_and_match_the_dispatcher():
    names = stats.names()
    assert len(names) == len(set(names)) == 15
    assert names == tuple(family.ALL_STATISTICS)
    assert set(stats.phase_unit()) == set(family.PHASE_UNIT)
    from inertialab.noise.statistics.gaps import GAP_STATISTICS

    assert set(stats.with_gaps()) == set(GAP_STATISTICS)


@pytest.mark.parametrize("entry", stats.STATISTICS, ids=lambda e: e.name)
def test_each_statistic_is_what_the_family_computes(entry):
    r = family.compute(entry.name, WHITE, rate_hz=10.0, taus="octave")
    own = entry.function(WHITE, rate_hz=10.0, taus="octave")
    assert r.statistic == own.statistic
    np.testing.assert_array_equal(r.dev, own.dev)
    np.testing.assert_array_equal(r.taus_s, own.taus_s)
    # the EDF model: no interval exactly when declared "none"
    assert (entry.edf == "none") == bool(np.all(np.isnan(r.edf)))


@pytest.mark.parametrize("entry", stats.STATISTICS, ids=lambda e: e.name)
def test_bias_correction_and_unit_flags_hold(entry):
    plain = family.compute(entry.name, WHITE, rate_hz=10.0)
    # Stable32's corrections apply to the identified noise type and are 1 for white
    # frequency noise (TOTDEV, Theo1): a random-walk record shows them
    rw = np.cumsum(WHITE)
    corr = family.compute(entry.name, rw, rate_hz=10.0, bias_correction=True)
    base = family.compute(entry.name, rw, rate_hz=10.0)
    assert (not np.array_equal(base.dev, corr.dev)) == entry.bias_correction
    # white rate noise: rate-unit deviations fall with tau (slope -1/2), phase-unit ones
    # (time error, its rms and maximum) grow; taus with many terms only
    ok = np.isfinite(plain.dev) & (plain.dev > 0) & (plain.n_terms >= WHITE.size // 8)
    slope = np.polyfit(np.log(plain.taus_s[ok]), np.log(plain.dev[ok]), 1)[0]
    assert (slope > 0) == entry.phase_unit, slope


def test_unknown_statistic_lookup():
    assert stats.get("OADEV").name == "oadev"
    with pytest.raises(KeyError):
        stats.get("xdev")


# ----------------------------------------------------------------- model types

def _tiny(tag):
    """A fitted instance of the types without a fixture file (seeded, small)."""
    x = np.linspace(0, 1, 30)[:, None]
    if tag == "mlp-lm":
        return TYPES[tag](hidden=2, max_epochs=3, rng=0).fit(np.hstack([x, x ** 2]), x[:, 0])
    if tag == "nar":
        return TYPES[tag](order=2, hidden=2, restarts=1).fit(5 + np.cumsum(RNG.normal(0, .1, 60)))
    return None


def _instances():
    for tag in MODEL_TYPES:
        files = sorted(MODELS.glob(f"{tag}-*v1.json"))
        yield tag, (load_model(files[0]) if files else _tiny(tag))


def test_registry_tags_classes_and_schemas_agree():
    assert set(SCHEMAS) == set(MODEL_TYPES)
    for tag, e in MODEL_TYPES.items():
        assert e.cls.MODEL_TYPE == tag and TYPES[tag] is e.cls
        assert e.kind in ("calibration", "learner", "noise")
        assert isinstance(e.version, int) and e.version >= 1
        assert e.schema is SCHEMAS[tag]
        assert (e.apply is None) == (e.kind == "noise")
        assert callable(e.apply) or e.apply is None


@pytest.mark.parametrize("tag,obj", list(_instances()), ids=[t for t in MODEL_TYPES])
def test_every_model_type_round_trips_through_its_file(tag, obj, tmp_path):
    assert obj is not None, f"{tag}: no fixture and no tiny fit"
    assert isinstance(obj, ModelContract)
    d = obj.to_dict()
    SCHEMAS[tag](d, "")                            # the payload passes its own schema
    back = load_model(save_model(obj, tmp_path / "m.json"), expected_type=tag)
    assert type(back) is type(obj)
    import json

    from inertialab.jsonable import to_jsonable

    assert json.dumps(to_jsonable(back.to_dict()), sort_keys=True) == \
        json.dumps(to_jsonable(d), sort_keys=True)


def test_loading_needs_the_registry_and_refuses_other_types(tmp_path):
    from inertialab.io import modelfile

    p = save_model(load_model(MODELS / "polynomial-v1.json"), tmp_path / "p.json")
    with pytest.raises(InputError, match="unknown model type 'polynomial'"):
        modelfile.load_model(p, types={})
    with pytest.raises(InputError, match="expected 'rbf'"):
        load_model(p, expected_type="rbf")
    with pytest.raises(TypeError, match="not a registered model type"):
        save_model(object(), tmp_path / "x.json")


# ----------------------------------------------------------------- file formats

def test_every_declared_suffix_is_recognised_as_its_format(tmp_path):
    from inertialab.io.formats.dispatch import format_of
    from inertialab.io.formats.registry import FORMATS

    assert len({f.name for f in FORMATS}) == len(FORMATS)
    for f in FORMATS:
        for suf in f.suffixes:
            if suf == "/":
                p = tmp_path / f"{f.name}_dir"
                p.mkdir()
            else:
                p = tmp_path / f"{f.name}{suf}"
                if f.name == "mat4":
                    body = b"\0\0\0\0" * 8
                elif f.name == "text":
                    body = b"t,x\n0,1\n"
                else:
                    body = f.magic + b"\0" * 600
                p.write_bytes(body)
            assert format_of(p) == f.name, (f.name, suf)


def test_format_options_are_reading_options_with_a_flag():
    import dataclasses

    from inertialab.cli.options import READING_PARAMS
    from inertialab.io.formats.registry import FORMATS
    from inertialab.io.mapping import ReadOptions

    fields = {f.name for f in dataclasses.fields(ReadOptions)}
    flags = {p.name for p in READING_PARAMS}
    via = {"parse": {"sep", "decimal", "skip_rows"}}
    for f in FORMATS:
        for opt in f.options:
            assert opt in fields, (f.name, opt)
            assert via.get(opt, {opt}) <= flags, (f.name, opt)
