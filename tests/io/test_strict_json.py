"""Model files, sidecars and mapping files are read strictly: a key given twice, ``true``
where a number belongs, an ADC declared with strings, a sidecar unit contradicting a
column suffix, and every payload field of the wrong shape or type are one line naming
the file and key."""

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from inertialab.calib import load_model
from inertialab.errors import InputError
from inertialab.io import read_record
from inertialab.io.sidecar import check_adc, read_sidecar

MODELS = Path(__file__).resolve().parents[1] / "data" / "models"


def _model(tmp_path, kind, edit=None, text_edit=None):
    env = json.loads((MODELS / f"{kind}-v1.json").read_text())
    if edit:
        edit(env["payload"])
    text = json.dumps(env)
    p = tmp_path / "m.json"
    p.write_text(text_edit(text) if text_edit else text)
    return p


def test_model_file_with_a_key_twice_is_refused(tmp_path):
    p = _model(tmp_path, "triaxial-calibration",
               text_edit=lambda t: t.replace('"method": "lm",', '"method": "lm", "method": '
                                             '"six-position",', 1))
    with pytest.raises(InputError, match="key 'method' appears twice"):
        load_model(p)


@pytest.mark.parametrize("kind, path, value, needle", [
    ("triaxial-calibration", ["iterations"], True, "iterations: must be an integer, got bool"),
    ("triaxial-calibration", ["g_local"], True, "g_local: must be a number, got bool"),
    ("thermal-compensation", ["regressor", "x_span", 0], "1.5",
     "regressor.x_span[0]: must be a number, got str"),
    ("thermal-compensation", ["regressor", "best_epoch"], True, "best_epoch: must be an integer"),
    ("thermal-compensation", ["regressor_type"], "pickle", "regressor_type: must be one of"),
    ("ferraris-calibration", ["gyro", "turns", "x_rot", "axis"], [0.0] * 600_000,
     "axis: must have 3 entries, got 600000"),
    ("ferraris-calibration", ["gyro", "rotation_deg"], "360", "rotation_deg: must be a number"),
    ("triaxial-calibration", ["stderr", "bx"], "0.1", "stderr.bx: must be a number"),
    ("triaxial-calibration", ["flags"], [1], "flags[0]: must be a string"),
])
def test_every_payload_field_has_its_type_and_shape(tmp_path, kind, path, value, needle):
    def edit(p):
        for k in path[:-1]:
            p = p[k]
        p[path[-1]] = value
    with pytest.raises(InputError) as exc:
        load_model(_model(tmp_path, kind, edit))
    assert needle in str(exc.value) and "m.json" in str(exc.value)


def _sidecar(tmp_path, text):
    (tmp_path / "r.meta.json").write_text(text)
    return tmp_path / "r.csv"


@pytest.mark.parametrize("text, needle", [
    ('{"fs_hz": 100, "fs_hz": 200}', "key 'fs_hz' appears twice"),
    ('{"fs_hz": true}', "key 'fs_hz' must be a number"),
    ('{"adc": {"bits": "16", "signed": "no"}}', "'adc.bits' must be an integer"),
    ('{"adc": {"bits": 16, "signed": "no"}}', "'adc.signed' must be true or false"),
    ('{"adc": {"bits": true, "signed": false}}', "'adc.bits' must be an integer"),
    ('{"adc": 16}', "key 'adc' must be an object"),
    ('{"adc": {"bits": 16, "signed": false, "vref": 3}}', "unknown entries vref"),
])
def test_sidecar_is_strict(tmp_path, text, needle):
    with pytest.raises(InputError, match=needle) as exc:
        read_sidecar(_sidecar(tmp_path, text))
    assert "r.meta.json" in str(exc.value)


def test_a_well_declared_adc_is_kept():
    assert check_adc({"bits": 16, "signed": False}) == {"bits": 16, "signed": False}


def test_unsigned_adc_declared_is_used_by_the_checks():
    from inertialab.calib.triaxial_checks import adc_range

    r = adc_range(np.zeros(3), {"bits": 16, "signed": False})
    assert (r.zero, r.source) == (32768.0, "declared")
    with pytest.raises(InputError, match="adc.signed"):
        adc_range(np.zeros(3), {"bits": 16, "signed": "no"})


def test_sidecar_unit_against_a_column_suffix(tmp_path):
    f = tmp_path / "r.csv"
    pd.DataFrame({"t_s": np.arange(50) / 10.0, "rate_dph": np.linspace(0, 1, 50)}).to_csv(
        f, index=False)
    (tmp_path / "r.meta.json").write_text('{"units": {"rate": "dps"}}')
    with pytest.raises(InputError, match="suffix says 'dph' but the header says units=dps"):
        read_record(f, "gyro_log")
    (tmp_path / "r.meta.json").write_text('{"units": {"rate": "dph"}}')  # the same: fine
    assert read_record(f, "gyro_log").units["rate_dph"] == "dph"


def test_mapping_file_with_a_key_twice_is_refused(tmp_path):
    from inertialab.io.mapping import load_map_file

    m = tmp_path / "m.json"
    m.write_text('{"columns": {"t_s": "a"}, "columns": {"t_s": "b"}}')
    with pytest.raises(InputError, match="appears twice"):
        load_map_file(m)


@pytest.mark.parametrize("kind, key, value, needle", [
    ("vibration-compensation", "poly_degree", "4", "poly_degree: must be an integer"),
    ("vibration-compensation", "rng", 1.5, "rng: must be an integer"),
    ("noise-terms", "alpha_model", [0] * 3 + ["x"], "alpha_model[3]: must be an integer"),
    ("dual-calibration", "units", {"KA0": 1}, "units.KA0: must be a string"),
    ("rbf", "centers", True, "centers"),
])
def test_fields_models_only_carry_are_typed_too(tmp_path, kind, key, value, needle):
    with pytest.raises(InputError, match=needle.replace("[", r"\[").replace("]", r"\]")):
        load_model(_model(tmp_path, kind, lambda p: p.__setitem__(key, value)))
