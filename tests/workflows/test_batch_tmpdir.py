"""``batch --scheduler local`` under a deep TMPDIR: the local cluster's fork server binds
a Unix socket under the temporary directory (a path of at most 107 bytes), so while it
starts the temporary directory is a short one; a socket path still too long is refused
in one line naming TMPDIR."""

import os
import socket
import subprocess
import sys
import tempfile
from multiprocessing import connection

import pytest

from inertialab.errors import InputError
from inertialab.workflows import batch as wb


@pytest.fixture
def deep_tmp(tmp_path, monkeypatch):
    """A temporary directory of 120 bytes or more, made the process's default."""
    deep = tmp_path / ("d" * 60) / ("e" * 60)
    deep.mkdir(parents=True)
    monkeypatch.setattr(tempfile, "tempdir", str(deep))
    return deep


def _bind_listener() -> str:
    """Bind a Unix socket where multiprocessing's fork server binds its own (a
    ``pymp-*`` directory under the temporary directory); return the path."""
    d = tempfile.mkdtemp(prefix="pymp-")
    addr = connection.arbitrary_address("AF_UNIX")
    addr = os.path.join(d, os.path.basename(addr))
    with socket.socket(socket.AF_UNIX) as s:
        try:
            s.bind(addr)
        finally:
            if os.path.exists(addr):
                os.unlink(addr)
            os.rmdir(d)
    return addr


def test_a_deep_tmpdir_is_too_long_for_the_socket(deep_tmp):
    with pytest.raises(OSError, match="AF_UNIX path too long"):
        _bind_listener()


def test_the_socket_binds_under_the_short_directory_and_tmpdir_is_restored(deep_tmp):
    with wb.short_temp_dir() as base:
        assert base == "/tmp"
        addr = _bind_listener()
    assert addr.startswith("/tmp/pymp-") and len(os.fsencode(addr)) < wb.UNIX_PATH_MAX
    assert tempfile.gettempdir() == str(deep_tmp)


def test_a_short_tmpdir_is_left_as_it_is(tmp_path, monkeypatch):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    if len(os.fsencode(str(tmp_path))) + 40 >= wb.UNIX_PATH_MAX:
        pytest.skip("this machine's tmp_path is itself deep")
    with wb.short_temp_dir() as base:
        assert base == str(tmp_path)


def test_a_socket_path_still_too_long_is_refused_naming_tmpdir(deep_tmp, monkeypatch):
    def too_long():
        raise OSError("AF_UNIX path too long")

    with pytest.raises(InputError, match="TMPDIR=") as e:
        wb._start_forkserver(too_long)
    assert "\n" not in str(e.value)
    assert tempfile.gettempdir() == str(deep_tmp)


@pytest.mark.slow  # a real LocalCluster in a fresh process: about 10 s
def test_batch_local_runs_under_a_deep_tmpdir(tmp_path):
    pytest.importorskip("dask.distributed")
    deep = tmp_path / ("d" * 60) / ("e" * 60)
    deep.mkdir(parents=True)
    log = tmp_path / "gyro.csv"
    env = os.environ | {"TMPDIR": str(deep), "MPLBACKEND": "Agg"}
    run = [sys.executable, "-m", "inertialab"]
    subprocess.run([*run, "simulate", "gyro-static", "--preset", "allan-test", "--hours",
                    "0.05", "--rate", "10", "--seed", "1", "--out", str(log)], env=env,
                   check=True, capture_output=True)
    res = subprocess.run([*run, "batch", "allan", "--inputs", str(log), "--scheduler",
                          "local", "--workers", "1", "--json"], env=env, capture_output=True,
                         text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert '"n_pass": 1' in res.stdout
    assert list(deep.iterdir()) == []  # the workers' scratch space removed
