"""Robustness sweep: every reader and every CLI command fed truncated files, binary
garbage, wrong encodings, huge and tiny numbers, NaN/inf, empty columns, duplicated
headers, and model files with edited fields. Each case must end in a result or a one-line
error with exit 2: never a traceback, a hang, or a partially written output file.

The number of cases tried per reader/command is printed in the test summary.
"""

from __future__ import annotations

import contextlib
import io
import json
import shutil
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from inertialab import InputError
from inertialab.calib.model_types import load_model
from inertialab.io import read_record

EXAMPLES = Path(__file__).resolve().parent.parent / "docs" / "examples"
KINDS = {
    "gyro_log.csv": "gyro_log",
    "thermal_tumble.csv": "thermal_tumble",
    "triaxial.static.csv": "triaxial_static",
    "triaxial.raw.csv": "triaxial_raw",
    "dual_tumble.csv": "dual_tumble",
    "storage_drift.csv": "storage_drift",
}
SETTINGS = settings(max_examples=25, deadline=None, derandomize=True,
                    suppress_health_check=list(HealthCheck))


def _counter():
    conftest = sys.modules.get("conftest") or sys.modules.get("tests.conftest")
    if conftest is None:
        for name, mod in sys.modules.items():
            if name.endswith("conftest") and hasattr(mod, "ROBUSTNESS_CASES"):
                return mod.ROBUSTNESS_CASES
        import collections

        return collections.Counter()
    return conftest.ROBUSTNESS_CASES


# ------------------------------------------------------------------ mutations of a file

WEIRD_VALUES = ["nan", "NaN", "inf", "-inf", "1e308", "-1e308", "1e-320", "0", "",
                "abc", "1,5", "0x10", "  ", "\u00e9", "1e999", "-0", "TRUE"]


@st.composite
def mutated_bytes(draw, original: bytes):
    text = original.decode("utf-8")
    lines = text.splitlines(keepends=True)
    kind = draw(st.sampled_from(["truncate", "garbage", "encoding", "cell", "empty_column",
                                 "dup_header", "drop_rows", "shuffle", "binary_prefix"]))
    if kind == "truncate":
        cut = draw(st.integers(0, max(0, len(original) - 1)))
        return original[:cut]
    if kind == "garbage":
        return draw(st.binary(min_size=1, max_size=400))
    if kind == "binary_prefix":
        return draw(st.binary(min_size=1, max_size=20)) + original
    if kind == "encoding":
        enc = draw(st.sampled_from(["utf-16", "latin-1", "utf-32"]))
        return (text + "\u00e9\u00b0").encode(enc, errors="replace")
    header_i = next((i for i, ln in enumerate(lines) if not ln.lstrip().startswith("#")), 0)
    header = lines[header_i].rstrip("\n").split(",")
    body = lines[header_i + 1:]
    if kind == "cell" and body:
        r = draw(st.integers(0, len(body) - 1))
        cells = body[r].rstrip("\n").split(",")
        c = draw(st.integers(0, len(cells) - 1))
        cells[c] = draw(st.sampled_from(WEIRD_VALUES))
        body[r] = ",".join(cells) + "\n"
    elif kind == "empty_column":
        c = draw(st.integers(0, len(header) - 1))
        body = [",".join("" if j == c else v for j, v in enumerate(b.rstrip("\n").split(","))) + "\n"
                for b in body]
    elif kind == "dup_header":
        c = draw(st.integers(0, len(header) - 1))
        d = draw(st.integers(0, len(header) - 1))
        header[d] = header[c]
    elif kind == "drop_rows":
        keep = draw(st.integers(0, len(body)))
        body = body[:keep]
    elif kind == "shuffle" and len(body) > 1:
        body = draw(st.permutations(body))
    out = "".join(lines[:header_i]) + ",".join(header) + "\n" + "".join(body)
    return out.encode("utf-8")


def _copy_with_sidecar(src: Path, dst_dir: Path, data: bytes) -> Path:
    dst = dst_dir / src.name
    dst.write_bytes(data)
    side = src.with_name(src.name.split(".")[0] + ".meta.json")
    if side.exists():
        shutil.copy(side, dst_dir / side.name)
    return dst


@pytest.mark.parametrize("name", sorted(KINDS))
def test_readers_never_crash(name, tmp_path_factory):
    original = (EXAMPLES / name).read_bytes()
    counter = _counter()

    @SETTINGS
    @given(data=mutated_bytes(original))
    def inner(data):
        d = tmp_path_factory.mktemp("r")
        p = _copy_with_sidecar(EXAMPLES / name, d, data)
        counter[f"read_record[{KINDS[name]}]"] += 1
        try:
            rec = read_record(p, KINDS[name])
        except InputError as exc:
            assert "\n" not in str(exc)
            return
        assert rec.n >= 1

    inner()


# ------------------------------------------------------------------ model files

@st.composite
def edited_envelope(draw, env: dict):
    env = json.loads(json.dumps(env))
    what = draw(st.sampled_from(["type", "format_version", "payload_key", "payload_value",
                                 "drop", "truncate"]))
    if what == "type":
        env["type"] = draw(st.sampled_from(["", "os.system", "polynomial ", None, 3, "rbf"]))
    elif what == "format_version":
        env["format_version"] = draw(st.sampled_from([0, -1, 2, 99, "1", None, 1.5, True]))
    elif what == "payload_key" and env["payload"]:
        key = draw(st.sampled_from(sorted(env["payload"])))
        del env["payload"][key]
    elif what == "payload_value" and env["payload"]:
        key = draw(st.sampled_from(sorted(env["payload"])))
        env["payload"][key] = draw(st.sampled_from([None, "x", [], {}, [1e308, -1e308], -1, 1e9]))
    elif what == "drop":
        env.pop(draw(st.sampled_from(sorted(env))))
    text = json.dumps(env)
    if what == "truncate":
        text = text[: draw(st.integers(0, len(text) - 1))]
    return text


def test_model_files_with_edited_fields(tmp_path_factory):
    import numpy as np

    from inertialab.io.modelfile import save_model
    from inertialab.learn.poly import PolynomialRegressor

    d0 = tmp_path_factory.mktemp("m")
    m = PolynomialRegressor(degree=2).fit(np.arange(6.0), np.arange(6.0) ** 2)
    env = json.loads(save_model(m, d0 / "m.json").read_text())
    counter = _counter()

    @SETTINGS
    @given(text=edited_envelope(env))
    def inner(text):
        p = tmp_path_factory.mktemp("m") / "m.json"
        p.write_text(text)
        counter["load_model"] += 1
        try:
            obj = load_model(p)
        except InputError as exc:
            assert "\n" not in str(exc)
            return
        obj.predict(np.array([1.0]))

    inner()


# ------------------------------------------------------------------ CLI commands

def run_cli(args: list[str]) -> tuple[int, str, str]:
    """Run the CLI in-process; return (exit code, stdout, stderr)."""
    from inertialab.cli.main import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            main(args)
            code = 0
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 1
    return code, out.getvalue(), err.getvalue()


def _registered_commands() -> set[str]:
    from inertialab.cli.main import full_command

    root = full_command()
    names = set()
    for name, cmd in root.commands.items():
        if cmd.hidden:  # old spellings: aliases of swept commands
            continue
        subs = getattr(cmd, "commands", None)
        if subs:
            names |= {f"{name} {s}" for s, c in subs.items() if not c.hidden}
        else:
            names.add(name)
    return names


#: Base inputs for the CLI sweep, written once per session by the virtual lab (small
#: settings) or taken from docs/examples: name -> (simulate argv | example path).
BASES = {
    "gyro": ["simulate", "gyro-static", "--preset", "allan-test", "--hours", "0.05",
             "--rate", "10", "--seed", "1", "--out", "{dir}/gyro.csv"],
    "thermal": ["simulate", "thermal-tumble", "--out", "{dir}/thermal.csv"],
    "tri_static": ["simulate", "triaxial-poses", "--scenario", "sphere100-clean",
                   "--out", "{dir}/tri.static.csv"],
    "tri_raw": ["simulate", "triaxial-poses", "--scenario", "rawlog62-counts",
                "--out", "{dir}/tri.raw.csv"],
    "dual": ["simulate", "dual-tumble", "--scenario", "S1", "--out", "{dir}/dual.csv"],
    "drift": ["simulate", "storage-drift", "--units", "2", "--days", "60",
              "--out", "{dir}/drift.csv"],
    "vib_sweep": ["simulate", "fog-vibration", "--experiment", "sweep", "--p1-s", "40",
                  "--p3-s", "40", "--sweep-oct-per-min", "60", "--out", "{dir}/vs.csv"],
    "vib_fixed": ["simulate", "fog-vibration", "--experiment", "fixed", "--p1-s", "40",
                  "--p3-s", "40", "--p2-s", "40", "--out", "{dir}/vf.csv"],
    "ferraris": ["simulate", "ferraris-session", "--out", "{dir}/fer.raw.csv"],
}
#: models fitted once from the bases: name -> argv (``{dir}`` = the base directory)
MODELS = {
    "thermal_model": ["thermal", "fit", "{dir}/thermal.csv", "--method", "poly-2d",
                      "--out", "{dir}/thermal_fit"],
    "tri_model": ["triaxial", "fit", "{dir}/tri.static.csv", "--method", "lm",
                  "--out", "{dir}/tri_fit"],
    "vib_model": ["vibration", "fit", "{dir}/vs.csv", "--out", "{dir}/vib_fit"],
    "drift_model": ["drift", "fit", "{dir}/drift.csv", "--quantity", "bias", "--order", "1",
                    "--restarts", "1", "--horizon", "5", "--out", "{dir}/drift_fit"],
}
MODEL_FILES = {"thermal_model": "thermal_fit/model.json", "tri_model": "tri_fit/model.json",
               "drift_model": "drift_fit/model.json", "vib_model": "vib_fit/model.json"}

#: command -> list of (mutated input, argv template). ``{file}`` is the mutated copy,
#: ``{out}`` an output path inside the case directory, ``{dir}`` the base directory.
#: Canonical spellings; the hidden old spellings are aliases of these.
CLI_CASES = {
    "validate": [("ex:gyro_log.csv", ["validate", "{file}", "--kind", "gyro_log"]),
                 ("ex:triaxial.static.csv", ["validate", "{file}", "--kind", "triaxial_static"]),
                 ("ex:storage_drift.csv", ["validate", "{file}", "--kind", "storage_drift"])],
    "allan": [("gyro", ["allan", "{file}", "--json"]),
              ("ex:vendors/vectornav.csv",
               ["allan", "{file}", "--imu", "--map-file",
                "{examples}/vendors/vectornav.map.json", "--json"])],
    "thermal fit": [("thermal", ["thermal", "fit", "{file}", "--method", "poly-2d", "--json"])],
    "thermal apply": [("thermal", ["thermal", "apply", "{dir}/thermal_fit/model.json",
                                   "{file}", "--out", "{out}.csv"]),
                      ("thermal_model", ["thermal", "apply", "{file}", "{dir}/thermal.csv",
                                         "--out", "{out}.csv"])],
    "thermal export": [("thermal_model", ["thermal", "export", "{file}", "--c", "{out}"])],
    "triaxial fit": [("tri_static", ["triaxial", "fit", "{file}", "--method", "lm", "--json"]),
                     ("tri_raw", ["triaxial", "fit", "{file}", "--method", "lm",
                                  "--k-thr", "6", "--json"])],
    "triaxial ferraris": [("ferraris", ["triaxial", "ferraris", "{file}", "--json"])],
    "triaxial apply": [("tri_static", ["triaxial", "apply", "{dir}/tri_fit/model.json",
                                       "{file}", "--out", "{out}.csv"]),
                       ("tri_model", ["triaxial", "apply", "{file}", "{dir}/tri.static.csv",
                                      "--out", "{out}.csv"])],
    "triaxial export": [("tri_model", ["triaxial", "export", "{file}", "--to", "kalibr",
                                       "--out", "{out}.yaml"])],
    "dual fit": [("dual", ["dual", "fit", "{file}", "--method", "ls", "--json"])],
    "drift fit": [("drift", ["drift", "fit", "{file}", "--quantity", "bias", "--order", "1",
                             "--restarts", "1", "--horizon", "5", "--json"])],
    "drift evaluate": [("drift", ["drift", "evaluate", "{file}", "--quantity", "bias",
                                  "--order", "1", "--restarts", "1", "--horizon", "5",
                                  "--first", "40", "--step", "10", "--json"])],
    "drift forecast": [("drift_model", ["drift", "forecast", "{file}", "--json"])],
    "drift apply": [("drift", ["drift", "apply", "{dir}/drift_fit/model.json", "{file}",
                               "--out", "{out}.csv"]),
                    ("drift_model", ["drift", "apply", "{file}", "{dir}/drift.csv",
                                     "--out", "{out}.csv"])],
    "vibration fit": [("vib_fixed", ["vibration", "fit", "{dir}/vs.csv", "{file}", "--json"])],
    "vibration apply": [("vib_fixed", ["vibration", "apply", "{dir}/vib_fit/model.json",
                                       "{file}", "--out", "{out}.csv"]),
                        ("vib_model", ["vibration", "apply", "{file}", "{dir}/vf.csv",
                                       "--out", "{out}.csv"])],
    "batch": [("gyro", ["batch", "allan", "--inputs", "{casedir}/*.csv", "--scheduler",
                        "serial", "--json"])],
}


@pytest.fixture(scope="module")
def base_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("bases")
    for argv in list(BASES.values()) + list(MODELS.values()):
        code, _, err = run_cli([a.format(dir=d) for a in argv])
        assert code == 0, f"{argv}: {err}"
    return d


def _source(name: str, base: Path) -> Path:
    if name.startswith("ex:"):
        return EXAMPLES / name[3:]
    if name in MODEL_FILES:
        return base / MODEL_FILES[name]
    argv = BASES[name]
    return Path(argv[argv.index("--out") + 1].format(dir=base))


def _mutation(src: Path):
    original = src.read_bytes()
    if src.suffix == ".json":
        return edited_envelope(json.loads(original))
    return mutated_bytes(original)


def _cases():
    for cmd, cases in CLI_CASES.items():
        for i, (source, args) in enumerate(cases):
            yield pytest.param(cmd, source, args, id=f"{cmd.replace(' ', '-')}-{i}")


@pytest.mark.parametrize("cmd, source, args", list(_cases()))
def test_cli_commands_end_in_result_or_one_line_error(cmd, source, args, base_dir,
                                                      tmp_path_factory):
    src = _source(source, base_dir)
    counter = _counter()

    @settings(max_examples=8, deadline=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    @given(data=_mutation(src))
    def inner(data):
        d = tmp_path_factory.mktemp("c")
        p = d / src.name
        p.write_bytes(data.encode() if isinstance(data, str) else data)
        side = src.with_name(src.name.split(".")[0] + ".meta.json")
        if side.exists():
            shutil.copy(side, d / side.name)
        out = d / "out"
        argv = [a.format(file=p, out=out, dir=base_dir, casedir=d, examples=EXAMPLES)
                for a in args]
        counter[f"cli: {cmd}"] += 1
        code, stdout, stderr = run_cli(argv)
        assert "Traceback" not in stderr
        assert code in (0, 2), f"exit {code}: {stderr}"
        if code == 2:
            assert len(stderr.strip().splitlines()) == 1, stderr
            assert not list(d.glob("**/.*.tmp")), "temporary output left behind"
            assert not (d / "out.csv").exists(), "partial output written on error"
        elif "--json" in argv:
            json.loads(stdout)

    inner()


def test_every_registered_command_is_swept():
    """A new command must join CLI_CASES (or be listed here as taking no input file)."""
    no_input = {"demo", "simulate", "dual design"}
    registered = _registered_commands()
    missing = sorted(c for c in registered
                     if c not in CLI_CASES and c not in no_input and not c.startswith("simulate"))
    assert not missing, f"commands not in the robustness sweep: {missing}"


# ------------------------------------------------------------------ main's last line of defence

def test_user_errors_from_the_environment_are_exit_2_lines():
    """Exceptions that bad input or the machine cause map to one line
    naming the file; a genuine bug does not."""
    import errno

    from inertialab.cli.main import user_error

    files = ["in.csv"]
    assert "not enough memory" in user_error(MemoryError(), files) and "in.csv" in \
        user_error(MemoryError(), files)
    assert "nested too deeply (in.csv)" in user_error(RecursionError(), files)
    assert user_error(OSError(errno.ENOSPC, "No space left on device", "/o/x.csv"),
                      files) == "/o/x.csv: No space left on device"
    assert user_error(OSError(errno.EROFS, "Read-only file system"), files) == \
        "in.csv: Read-only file system"
    exc = UnicodeDecodeError("utf-8", b"\xff", 0, 1, "invalid start byte")
    assert user_error(exc, files) == "input is not UTF-8 text (in.csv) (byte 0xff at offset 0)"
    assert "too large" in user_error(OverflowError("int too large to convert"), files)
    try:
        int("9" * 5000)
    except ValueError as e:
        assert "too many digits" in user_error(e, files)
    assert user_error(ZeroDivisionError("bug"), files) is None
    assert user_error(BrokenPipeError(errno.EPIPE, "pipe"), files) is None


@pytest.mark.parametrize("argv, what", [
    (["allan", "x.csv", "--rate", "1e308"], "--rate must be"),
    (["allan", "x.csv", "--rate=1e-308"], "--rate must be"),
    (["allan", "x.csv", "--rate", "nan"], "--rate must be"),
    (["vibration", "fit", "x.csv", "--rate", "1e308"], "--rate must be a rate between"),
    (["thermal", "fit", "x.csv", "--try-number", "20000"], "--try-number must be from 1 to"),
    (["drift", "fit", "x.csv", "--tol-bias-ug", "0"], "--tol-bias-ug must be from 1e-09"),
    (["allan", "x.csv", "--taus", "1e11"], "--taus in seconds"),
    (["allan", "x.csv", "--taus", "99999999999999"], "--taus count"),
    (["dual", "design", "--positions", "100000000"], "--positions"),
    (["drift", "forecast", "m.json", "--horizon", "100000000"], "--horizon"),
    (["simulate", "gyro-static", "--out", "/dev/null"], "--out is a device"),
])
def test_size_arguments_and_device_outputs_refused_before_any_work(argv, what):
    code, out, err = run_cli(argv)
    assert code == 2 and err.count("\n") == 1 and what in err, err


def test_warnings_print_as_one_line_and_handlers_are_restored():
    import signal
    import warnings

    from inertialab.cli.main import _one_line_warning

    buf = io.StringIO()
    _one_line_warning(RuntimeWarning("overflow encountered\nin multiply"), RuntimeWarning,
                      "/x/numpy/core.py", 12, file=buf, line="  y = a * b")
    assert buf.getvalue() == "warning: RuntimeWarning: overflow encountered in multiply\n"
    show, term = warnings.showwarning, signal.getsignal(signal.SIGTERM)
    run_cli(["--version"])
    assert warnings.showwarning is show and signal.getsignal(signal.SIGTERM) is term


# --------------------------------------------------------------------------------------
# limits.py and signals.py: the one place for budgets, bounds and the signal handler

def test_budget_and_bounds_refuse_with_one_line(monkeypatch):
    import math

    from inertialab import limits

    monkeypatch.delenv("INERTIALAB_MAX_BYTES", raising=False)
    assert limits.memory_budget() == 2**30
    limits.check_budget(2**30, "x")  # at the budget: fine
    with pytest.raises(InputError, match=r"x needs 2 GiB, above the memory budget of 1 GiB"):
        limits.check_budget(2**31, "x", "f.h5")
    with pytest.raises(InputError, match="unbounded amount"):
        limits.check_budget(math.inf, "x")
    monkeypatch.setenv("INERTIALAB_MAX_BYTES", "4e9")
    assert limits.memory_budget() == 4_000_000_000
    monkeypatch.setenv("INERTIALAB_MAX_BYTES", "nonsense")
    assert limits.memory_budget() == 2**30
    assert limits.bounded("g_local", 9.8, 1, 100) == 9.8 and limits.bounded("x", None) is None
    for bad in (float("nan"), float("inf"), 0.5, 101, "abc", True):
        with pytest.raises(InputError, match="argument 'g_local'"):
            limits.bounded("g_local", bad, 1, 100)
    with pytest.raises(InputError, match=r"in \(0, 1\]"):
        limits.bounded("q", 0.0, 0, 1, lo_open=True)
    assert limits.bounded_int("order", 3.0, 1, 10) == 3
    with pytest.raises(InputError, match="whole number"):
        limits.bounded_int("order", 2.5, 1, 10)
    with pytest.raises(InputError, match=r"'m\[1, 0\]' is 1e\+200"):
        limits.finite("m", [[1.0, 2.0], [1e200, 0.0]])
    limits.finite("m", [[1.0, -1e100]])


def test_regular_input_kinds(tmp_path):
    import os

    from inertialab import limits

    (tmp_path / "f.csv").write_text("x\n")
    assert limits.regular_input(tmp_path / "f.csv") == tmp_path / "f.csv"
    os.mkfifo(tmp_path / "p.csv")
    with pytest.raises(InputError, match="is a FIFO"):
        limits.regular_input(tmp_path / "p.csv")
    with pytest.raises(InputError, match="is a directory"):
        limits.regular_input(tmp_path)
    assert limits.regular_input(tmp_path, allow_dir=True) == tmp_path
    with pytest.raises(InputError, match="no such file"):
        limits.regular_input(tmp_path / "missing.csv")


def test_signal_handler_installs_raises_and_restores():
    import signal

    from inertialab import signals

    old = signal.getsignal(signal.SIGTERM)
    signals.install()
    try:
        with pytest.raises(signals.Terminated) as exc:
            signal.raise_signal(signal.SIGTERM)
        assert exc.value.signum == signal.SIGTERM and signals.received() == [signal.SIGTERM]
        assert signals.interrupted_line(signal.SIGTERM) == \
            "error: interrupted by SIGTERM; nothing was written\n"
        assert "after the outputs were complete" in signals.interrupted_line(
            signal.SIGINT, after_commit=True)
    finally:
        signals.restore()
    assert signal.getsignal(signal.SIGTERM) is old


def test_library_bounds_hold_without_the_command_line():
    from inertialab.seeding import as_generator
    from inertialab.sim import gyro_static
    from inertialab.workflows.batch import run_batch
    from inertialab.workflows.drift import FitConfig

    with pytest.raises(InputError, match="argument 'tol_bias_ug'"):
        FitConfig(tol_bias_ug=float("nan")).validate()
    with pytest.raises(InputError, match="argument 'order'"):
        FitConfig(order=10**9).validate()
    with pytest.raises(InputError, match="argument 'seed' must be >= 0"):
        as_generator(-1)
    with pytest.raises(InputError, match="memory budget"):
        gyro_static.simulate(hours=100, rate_hz=100)
    with pytest.raises(InputError, match="argument 'workers'"):
        run_batch("allan", ["x.csv"], workers=10**9)


def test_input_globs_are_bounded_and_match_like_glob(tmp_path):
    import glob

    from inertialab.workflows.batch import expand_inputs

    for rel in ("a/x1.csv", "a/b/x2.csv", "a/b/c/x3.csv", "a/.hidden/x4.csv", "a/x1.meta.json",
                "a/b/y.txt", "z[1].csv"):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text("t_s,x\n")
    for pat in ("a/**/*.csv", "a/*/x?.csv", "a/**", "*.csv"):
        want = sorted(p for p in map(Path, glob.glob(str(tmp_path / pat), recursive=True))
                      if p.is_file() and not p.name.endswith(".meta.json"))
        assert expand_inputs(str(tmp_path / pat)) == want, pat
    assert expand_inputs(str(tmp_path / "z[1].csv")) == [tmp_path / "z[1].csv"]
    with pytest.raises(InputError, match="scans more than .* directories"):
        expand_inputs(str(tmp_path / "**" / "*.csv"), max_dirs=2)
    with pytest.raises(InputError, match="matches no file"):
        expand_inputs(str(tmp_path / "nothing*.csv"))
