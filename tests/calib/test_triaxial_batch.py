"""calib.triaxial_batch: chunked and streamed fleet calibration."""

import tracemalloc

import numpy as np
import pandas as pd

from inertialab.calib.triaxial_batch import calibrate_batch, iter_calibrate_batch
from inertialab.sim import triaxial_poses as tp
from inertialab.workflows.triaxial import static_data_from_frame


def _chunks(n_chunks, units, m=18):
    for i in range(n_chunks):
        rec = tp.simulate_line(units, seed=100 + i)
        sd = static_data_from_frame(rec.data, rec.meta)
        ids = np.array([f"c{i}-{u}" for u in range(units)])
        yield ids, sd.a.reshape(units, m, 3), sd.ref.reshape(units, m, 3)


def test_chunking_does_not_change_the_result():
    rec = tp.simulate_line(300, seed=3)
    sd = static_data_from_frame(rec.data, rec.meta)
    whole = calibrate_batch(sd, chunk_units=10_000)
    chunked = calibrate_batch(sd, chunk_units=64)
    pd.testing.assert_frame_equal(whole.table, chunked.table)
    assert np.array_equal(whole.X, chunked.X)


def test_streamed_memory_does_not_grow_with_the_fleet():
    # the generator's input chunks are made on the fly; what the stream holds is one input
    # chunk, one solver chunk and one output table, whatever the number of chunks
    def peak(n_chunks):
        tracemalloc.start()
        rows = 0
        for table in iter_calibrate_batch(_chunks(n_chunks, 400), chunk_units=200):
            rows += len(table)  # a consumer that writes each table out keeps nothing
        p = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        return p, rows

    p2, r2 = peak(2)
    p6, r6 = peak(6)
    assert r2 == 800 and r6 == 2400
    assert p6 < 1.15 * p2  # 3x the units, (nearly) the same peak
    # and the working set per solved unit is the solver's, not the fleet's: < 25 KB
    assert p2 / 400 < 25_000


def test_streamed_tables_equal_the_in_memory_batch():
    (ids, A, R), = list(_chunks(1, 250))
    streamed = pd.concat(list(iter_calibrate_batch([(ids, A, R)], chunk_units=100)),
                         ignore_index=True)
    from inertialab.calib.triaxial_session import StaticData

    sd = StaticData(a=A.reshape(-1, 3), ref=R.reshape(-1, 3), g=9.8, raw_unit="mps2",
                    raw_scale=1.0, raw_offset=0.0, counts=False, unit_id=np.repeat(ids, 18))
    whole = calibrate_batch(sd).table.set_index("unit_id").loc[streamed["unit_id"]]
    assert np.allclose(streamed[["kx", "theta_zx"]].to_numpy(), whole[["kx", "theta_zx"]]
                       .to_numpy(), rtol=0, atol=1e-12)
