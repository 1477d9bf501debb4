"""Hostile input to the readers: size and NUL checks before
parsing, bounded memory, one-line errors naming the file."""

import os
import resource
import time

import numpy as np
import pytest
from tests.helpers import run_cli

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
    res = run_cli("validate", p, "--kind", "gyro_log")
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


# --------------------------------------------------------------------------------------
# declared sizes, external data, regular files, outputs that would replace an input
# (docs/robustness.md promises 10-13); budgets set small so that nothing big is built

def _mat_with_compressed_zeros(path, n_rows):
    """A MATLAB v5 file: one compressed n_rows x 1 double variable 'imu' of zeros."""
    import struct
    import zlib

    def el(t, data):
        return struct.pack("<II", t, len(data)) + data + b"\0" * (-len(data) % 8)

    body = (el(6, struct.pack("<II", 6, 0)) + el(5, struct.pack("<ii", n_rows, 1)) +
            el(1, b"imu") + el(9, bytes(8 * n_rows)))
    comp = zlib.compress(struct.pack("<II", 14, len(body)) + body)
    head = b"MATLAB 5.0 MAT-file".ljust(116, b" ") + bytes(8) + struct.pack("<H", 0x0100) + b"IM"
    path.write_bytes(head + struct.pack("<II", 15, len(comp)) + comp)
    return path


def test_mat_budget_counts_inflated_bytes(tmp_path, monkeypatch):
    from inertialab.io.formats.matlab import _mat5_decompressed_bytes

    p = _mat_with_compressed_zeros(tmp_path / "z.mat", 100_000)  # 800 kB inflated, ~1 kB
    assert p.stat().st_size < 10_000
    n = _mat5_decompressed_bytes(p)
    assert 800_000 < n < 800_200  # the matrix header and sub-element tags on top
    monkeypatch.setenv("INERTIALAB_MAX_BYTES", "500000")
    with pytest.raises(InputError, match="needs more than .* memory budget") as exc:
        read_record(p, "gyro_log")
    assert str(p) in str(exc.value)
    monkeypatch.setenv("INERTIALAB_MAX_BYTES", "2000000")  # under the budget: read
    with pytest.raises(InputError, match="columns found: imu"):
        read_record(p, "gyro_log")


def test_hdf5_declared_size_external_data_and_links(tmp_path, monkeypatch):
    h5py = pytest.importorskip("h5py")
    monkeypatch.setenv("INERTIALAB_MAX_BYTES", "1e6")
    with h5py.File(tmp_path / "big.h5", "w") as fh:  # 8 MB declared, a few kB on disk
        fh.create_dataset("imu", shape=(1_000_000,), dtype="f8", compression="gzip")
    with pytest.raises(InputError, match=r"dataset 'imu' \(\(1000000,\) values\) needs"):
        read_record(tmp_path / "big.h5", "gyro_log")
    (tmp_path / "secret.bin").write_bytes(np.arange(10.0).tobytes())
    with h5py.File(tmp_path / "ext.h5", "w") as fh:
        fh.create_dataset("imu", shape=(10,), dtype="f8",
                          external=[(str(tmp_path / "secret.bin"), 0, 80)])
    with pytest.raises(InputError, match="external file"):
        read_record(tmp_path / "ext.h5", "gyro_log")
    with h5py.File(tmp_path / "link.h5", "w") as fh:
        fh["imu"] = h5py.ExternalLink(str(tmp_path / "ext.h5"), "/imu")
        fh["a"] = h5py.SoftLink("/b")
        fh["b"] = h5py.SoftLink("/a")
    with pytest.raises(InputError, match="external link"):
        read_record(tmp_path / "link.h5", "gyro_log", options=_dataset("imu"))
    with pytest.raises(InputError, match="looping soft link"):
        read_record(tmp_path / "link.h5", "gyro_log", options=_dataset("a"))


def _dataset(name):
    from inertialab.io.mapping import ReadOptions

    return ReadOptions(dataset=name)


class _Hung(Exception):
    pass


def _within(seconds):
    """Fail (instead of hanging the suite) when the block runs longer than ``seconds``."""
    import contextlib
    import signal

    @contextlib.contextmanager
    def guard():
        def ring(signum, frame):
            raise _Hung(f"still running after {seconds} s")

        old = signal.signal(signal.SIGALRM, ring)
        signal.alarm(seconds)
        try:
            yield
        finally:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, old)
    return guard()


@pytest.mark.parametrize("suffix", [".csv", ".npy", ".mat", ".h5", ".bag", ".ulg", ".parquet"])
def test_fifo_inputs_are_refused_without_opening(tmp_path, suffix):
    f = tmp_path / f"in{suffix}"
    os.mkfifo(f)
    with _within(10), pytest.raises(InputError, match="is a FIFO, not a regular file") as exc:
        read_record(f, "gyro_log")
    assert str(f) in str(exc.value)


def test_device_behind_a_data_name_is_refused(tmp_path):
    (tmp_path / "zero.bag").symlink_to("/dev/zero")
    with _within(10), pytest.raises(InputError, match="is a device"):
        read_record(tmp_path / "zero.bag", "gyro_log")


def test_outputs_never_replace_an_input_or_its_sidecar(tmp_path):
    from inertialab.io.outputs import OutputError, transaction
    from inertialab.io.writers import atomic_write_text, write_record

    rec = tmp_path / "rec.csv"
    rec.write_text("t_s,x\n0,1\n")
    side = tmp_path / "rec.meta.json"
    side.write_text("{}\n")
    for target in (rec, tmp_path / "rec.parquet"):  # the data file; its sidecar
        with pytest.raises(OutputError, match="would overwrite"):
            with transaction(protect=[rec]):
                write_record(__import__("pandas").DataFrame({"x": [1.0]}), target)
    assert rec.read_text() == "t_s,x\n0,1\n" and side.read_text() == "{}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rec.csv", "rec.meta.json"]
    with pytest.raises(OutputError, match="output path is empty"):
        with transaction():
            atomic_write_text("", "x")


def test_read_only_previous_output_is_refused_before_work(tmp_path, monkeypatch):
    from inertialab.io import outputs

    out = tmp_path / "out"
    (out / "sub").mkdir(parents=True)
    (out / outputs.MARKER).write_text("{}")
    real = os.access
    monkeypatch.setattr(outputs.os, "access",
                        lambda p, mode: False if str(p).endswith("sub") else real(p, mode))
    with pytest.raises(outputs.OutputError, match="'.*sub' is read-only"):
        with outputs.transaction() as tx:
            tx.stage_dir(out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no staging left


@pytest.mark.parametrize("cell", ['"4pos;tumble"', '"4pos|tumble"', '"4pos\ntumble"',
                                  '"a b c"'])
def test_quoted_cells_do_not_decide_the_separator(tmp_path, cell):
    from inertialab.io.formats.text import load_text

    f = tmp_path / "q.csv"
    f.write_text("unit,day,bias_mg,method\n" + "".join(
        f"U1,{i},0.{i}5,{cell}\n" for i in range(6)))
    t = load_text(f)
    assert t.layout.sep == "," and list(t.frame.columns) == ["unit", "day", "bias_mg", "method"]
    assert len(t.frame) == 6 and t.frame["bias_mg"].iloc[2] == pytest.approx(0.25)
    assert t.frame["method"].iloc[0] == cell.strip('"')


def test_decimal_commas_in_a_comma_file_and_huge_headers_are_one_line(tmp_path):
    from inertialab.io.formats.text import load_text

    f = tmp_path / "dc.csv"
    f.write_text("t_s,x\n" + "".join(f"{i},1,5\n" for i in range(5)))
    with pytest.raises(InputError, match="header names 2 columns but the data rows have 3 "
                                         "fields .decimal commas") as exc:
        load_text(f)
    assert str(f) in str(exc.value)
    wide = tmp_path / "wide.csv"
    wide.write_text(",".join(f"c{i}" for i in range(20_000)) + "\n" + ",".join(["1"] * 20_000))
    with pytest.raises(InputError, match="20000 fields, more than the 10000 columns") as exc:
        load_text(wide)
    assert str(wide) in str(exc.value)


def test_stated_rate_must_agree_with_the_time_stamps(tmp_path):
    f = tmp_path / "g.csv"
    f.write_text("t_s,rate_dph\n" + "".join(f"{i * 1e-7:.7e},{i % 7}\n" for i in range(200)))
    (tmp_path / "g.meta.json").write_text('{"fs_hz": 10}')
    # one check, where the time base is decided (io.timestamps.decide_timebase)
    with pytest.raises(InputError, match="fs_hz = 10 Hz contradicts the time stamps"):
        read_record(f, "gyro_log")
    (tmp_path / "g.meta.json").write_text('{"fs_hz": 1.02e7}')  # within 5 %: read
    assert read_record(f, "gyro_log").meta["fs_hz"] == pytest.approx(1.02e7)
