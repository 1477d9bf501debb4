"""Fleets on Dask: a 200-unit triaxial lot, parallel == serial."""

import numpy as np
import pytest

from inertialab.cli.batch import expand_inputs, parse_tolerance
from inertialab.errors import InputError
from inertialab.sim.triaxial_poses import simulate_line
from inertialab.workflows.batch import open_client, run_batch, run_unit

pytest.importorskip("dask.distributed")

N_UNITS = 200


@pytest.fixture(scope="module")
def client():
    with open_client("local", workers=2) as cl:
        yield cl


@pytest.fixture(scope="module")
def lot(tmp_path_factory):
    """200 simulated triaxial units (spec 002 line batch, rig18), one static file each,
    plus one broken file."""
    d = tmp_path_factory.mktemp("lot7")
    sim = simulate_line(N_UNITS, seed=7)
    for uid, frame in sim.data.groupby("unit_id", sort=True):
        frame.to_csv(d / f"{uid}.csv", index=False)   # g_local comes from the options
    (d / "U99999.csv").write_text("unit_id,pos_id,ax_mps2\nU99999,1,0.1\n")
    return d, sim.truth["X"]


def test_lot_parallel_equals_serial_and_truth(lot, client):
    d, X = lot
    paths = expand_inputs(str(d / "*.csv"))
    assert len(paths) == N_UNITS + 1
    checks = parse_tolerance("abs(bx)<=0.3,abs(by)<=0.3,kx=0.98..1.02")
    par = run_batch("calibrate-triaxial", paths, checks=checks, client=client,
                    options={"g_local": 9.8})
    ser = run_batch("calibrate-triaxial", paths, checks=checks, scheduler="serial",
                    options={"g_local": 9.8})
    # the same per-unit function on the same file: identical numbers, unit for unit
    assert [u.unit for u in par.units] == [u.unit for u in ser.units]
    for a, b in zip(par.units, ser.units):
        assert a.status == b.status and a.failed == b.failed and a.reason == b.reason
        assert a.figures == b.figures
    # the broken file is one error row with a one-line reason; the lot goes on
    bad = par.units[-1]
    assert bad.status == "error" and "ay" in bad.reason and "\n" not in bad.reason
    # against the simulated truth (field LM, norm objective): rig18 with 3 mm/s^2
    # noise gives bias errors of a few mm/s^2; 0.02 m/s^2 is ~5 sigma of that spread
    est = np.array([[u.figures[k] for k in ("bx", "by", "bz")] for u in par.units[:-1]])
    assert np.max(np.abs(est - X[:, 0:3])) < 0.02
    kx = np.array([u.figures["kx"] for u in par.units[:-1]])
    assert np.max(np.abs(kx - X[:, 3])) < 2e-3   # ~5 sigma of a 3e-4 scale-factor error
    # pass/fail agrees with the checks applied to the truth-near estimates
    expect = (np.abs(est[:, 0]) <= 0.3) & (np.abs(est[:, 1]) <= 0.3) & (np.abs(kx - 1) <= 0.02)
    assert [u.status == "pass" for u in par.units[:-1]] == expect.tolist()
    s = par.summary()
    assert s["n_units"] == N_UNITS + 1 and s["n_error"] == 1
    assert s["n_pass"] == int(expect.sum()) and s["yield"] == pytest.approx(expect.sum() / 201)
    assert par.workers == 2 and len(par.table()) == N_UNITS + 1


def test_run_unit_bad_command_and_missing_figure(lot):
    d, _ = lot
    with pytest.raises(InputError, match="batch command"):
        run_unit("nope", d / "U00000.csv")
    r = run_unit("calibrate-triaxial", d / "U00000.csv", {"g_local": 9.8},
                 parse_tolerance("adev_1s<=1"))
    assert r.status == "fail" and "no figure 'adev_1s'" in r.failed[0]
