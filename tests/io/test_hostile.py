"""Hostile input to the readers (issue 19 items 3, 7, 9): size and NUL checks before
parsing, bounded memory, one-line errors naming the file."""

import os
import resource
import subprocess
import sys
import time

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.io import peek_columns, read_record
from inertialab.io.sidecar import read_schedule


def _sparse(path, size):
    with open(path, "wb") as fh:
        fh.truncate(size)
    return path


@pytest.mark.parametrize("name", ["big.csv", "big.txt", "big.mat", "big.raw.csv"])
def test_sparse_2gb_file_fails_fast_in_bounded_memory(tmp_path, name):
    p = _sparse(tmp_path / name, 2 * 2**30)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t0 = time.perf_counter()
    said = r"binary content \(NUL byte at byte 0\)|MATLAB file .*first 20 bytes == 0"
    with pytest.raises(InputError, match=said) as exc:
        read_record(p, "gyro_log")
    with pytest.raises(InputError, match=said):
        peek_columns(p)
    elapsed = time.perf_counter() - t0
    grown_mib = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024
    assert "\n" not in str(exc.value) and str(p) in str(exc.value)
    assert elapsed < 2.0 and grown_mib < 64, (elapsed, grown_mib)


def test_sparse_tail_and_size_limit(tmp_path, monkeypatch):
    p = tmp_path / "tail.csv"
    with open(p, "wb") as fh:
        fh.write(b"t_s,rate_dph\n" + b"".join(b"%d,1\n" % i for i in range(10)))
        fh.truncate(64 * 2**20)  # data, then 64 MiB of NUL bytes
    with pytest.raises(InputError, match="NUL byte at byte"):
        read_record(p, "gyro_log")
    q = tmp_path / "ok.csv"
    q.write_text("t_s,rate_dph\n" + "".join(f"{i},1\n" for i in range(1000)))
    monkeypatch.setenv("INERTIALAB_MAX_TEXT_BYTES", "1000")
    with pytest.raises(InputError, match="above the reader's limit .* Parquet or .npy"):
        read_record(q, "gyro_log")


def test_sparse_npy_and_parquet_fail_with_one_line(tmp_path):
    for name in ("big.npy", "big.parquet"):
        p = _sparse(tmp_path / name, 2 * 2**30)
        t0 = time.perf_counter()
        with pytest.raises(InputError) as exc:
            read_record(p, "gyro_log", unit="dph", rate_hz=100.0)
        assert time.perf_counter() - t0 < 2.0 and str(p) in str(exc.value)


def test_validate_exits_2_on_the_sparse_file(tmp_path):
    p = _sparse(tmp_path / "big.csv", 2 * 2**30)
    res = subprocess.run([sys.executable, "-m", "inertialab", "validate", str(p), "--kind",
                          "gyro_log"], capture_output=True, text=True, timeout=120,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert res.returncode == 2 and res.stdout == ""
    assert len(res.stderr.strip().splitlines()) == 1 and "NUL byte" in res.stderr


@pytest.mark.parametrize("content, needle", [
    (b"\xff\xfet\x00_\x00s\x00", "UTF-16"),
    (b"t_s,rate_dph\n0,1\n\xc3\x28,2\n", "not UTF-8"),
])
def test_encodings_refused_before_parsing(tmp_path, content, needle):
    p = tmp_path / "e.csv"
    p.write_bytes(content)
    with pytest.raises(InputError, match=needle):
        read_record(p, "gyro_log")


@pytest.mark.parametrize("sidecar, needle", [
    ('{"fs_hz": "fast"}', "key 'fs_hz' must be a number"),
    ('{"fs_hz": 1e308}', "key 'fs_hz' must be a number between"),
    ('{"fs_hz": NaN}', "not valid JSON"),
    ('{"fs_hz": 0}', "key 'fs_hz'"),
    ('{"g_local_mps2": true}', "key 'g_local_mps2'"),
    ("[" * 100_000 + "]" * 100_000, "nested too deep|not valid JSON"),
    ('{"seed": ' + "9" * 5000 + "}", "not valid JSON"),
])
def test_sidecar_values_are_checked(tmp_path, sidecar, needle):
    p = tmp_path / "run.npy"
    np.save(p, np.zeros(100))
    (tmp_path / "run.meta.json").write_text(sidecar)
    with pytest.raises(InputError, match=needle) as exc:
        read_record(p, "gyro_log", unit="dph")
    assert "run.meta.json" in str(exc.value) and "\n" not in str(exc.value)


def test_header_key_fs_hz_checked_too(tmp_path):
    p = tmp_path / "h.csv"
    p.write_text("# fs_hz=abc\nrate_dph\n1\n2\n")
    with pytest.raises(InputError, match="key 'fs_hz' must be a number"):
        read_record(p, "gyro_log")


@pytest.mark.parametrize("content, needle", [
    (b"", "empty schedule file"),
    (b"\x00\x01\x02binary\x00", "NUL byte"),
    ("pos_id,pitch_deg,heading_deg\n1,0,0\n".encode("utf-16"), "UTF-16"),
    (b"pos_id,pitch_deg,heading_deg\n", "no rows"),
    (b"pos_id,x\n1,2\n", "needs columns pitch_deg and heading_deg, or face"),
])
def test_bad_schedule_files_are_one_line_naming_the_file(tmp_path, content, needle):
    p = tmp_path / "x.schedule.csv"
    p.write_bytes(content)
    with pytest.raises(InputError, match=needle) as exc:
        read_schedule(p)
    assert str(p) in str(exc.value) and "\n" not in str(exc.value)


def test_good_schedule_and_peek_columns(tmp_path):
    p = tmp_path / "x.schedule.csv"
    p.write_text("# rig18\nPos_ID, Pitch_deg, Heading_deg\n1,0,0\n2,90,0\n")
    s = read_schedule(p)
    assert list(s.columns) == ["pos_id", "pitch_deg", "heading_deg"] and len(s) == 2
    log = tmp_path / "x.raw.csv"
    log.write_bytes(b"\xef\xbb\xbfT_ms,ax_mps2\n0,1\n")
    assert peek_columns(log) == ["t_s", "ax_mps2"]
