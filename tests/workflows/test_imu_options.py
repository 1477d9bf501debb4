"""The six-axis options of ``allan --imu`` are refused before any work, naming the
argument (inertialab.workflows.imu_options), and a check log too short for a horizon is
said, not silent."""

import warnings

import pytest

from inertialab.errors import DataQualityWarning, InputError
from inertialab.workflows.imu_options import (
    MAX_HORIZONS,
    check_horizons,
    check_options,
    parse_horizons,
)


@pytest.mark.parametrize("text, needle", [
    (",".join(str(i + 1) for i in range(10_000)), "10000 horizons"),
    ("1,10,1", "horizon 1 s twice"), ("1,,10", "empty horizon"), ("", "empty horizon"),
    ("1e308", "must be in"), ("nan", "must be in"), ("-5", "must be in"),
    ("ten", "comma-separated seconds")])
def test_bad_horizons_are_one_line_naming_the_argument(text, needle):
    with pytest.raises(InputError, match=needle) as exc:
        parse_horizons(text)
    assert "predict_drift" in str(exc.value) and "\n" not in str(exc.value)


def test_good_horizons_parse_in_order():
    assert parse_horizons(" 1, 10,60 ") == (1.0, 10.0, 60.0)
    assert len(parse_horizons(",".join(str(i + 1) for i in range(MAX_HORIZONS)))) == \
        MAX_HORIZONS


def test_check_on_empty_or_the_analysed_file_is_refused(tmp_path):
    f = tmp_path / "imu.csv"
    f.write_text("x\n")
    with pytest.raises(InputError, match="check_on' is empty"):
        check_options(f, predict_drift="1", check_on="")
    with pytest.raises(InputError, match="analysed log itself"):
        check_options(f, predict_drift="1", check_on=str(tmp_path / "." / "imu.csv"))
    assert check_options(f, predict_drift="1", check_on="half") == (1.0,)


def test_method_and_topic_are_checked_before_reading(tmp_path):
    f = tmp_path / "missing.csv"  # never read: the options fail first
    with pytest.raises(InputError, match="'method'"):
        check_options(f, method="lsq")
    with pytest.raises(InputError, match="'rostopic'"):
        check_options(f, export=("kalibr", "k.yaml"), rostopic="/imu0\nevil: 1")


def test_horizon_longer_than_the_fitted_record_is_refused():
    with pytest.raises(InputError, match="horizon 600 s"):
        check_horizons((1.0, 600.0), 10.0, 600.0)
    check_horizons((1.0, 590.0), 10.0, 600.0)  # exactly fits


def test_check_data_without_a_window_warns_naming_the_horizons():
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        check_horizons((1.0, 25.0, 30.0), 10.0, 600.0, check_s=30.0, check_name="b.csv")
    msgs = [str(x.message) for x in w if issubclass(x.category, DataQualityWarning)]
    assert len(msgs) == 1 and "b.csv" in msgs[0] and "25, 30 s" in msgs[0]
