"""Hostile-input catalogue of the first fuzz (files, models, outputs, signals): one :class:`Case` per (class, command, input).

Commands are found through ``inertialab --help`` (:func:`discover`), so the catalogue
follows renamed commands: each recipe lists its spellings, newest first, and the first
one the CLI knows is used. Every case runs in its own directory and is checked against
the invariants of docs/robustness.md (:func:`violations`):

- exit 0 or 2 (130/143 for signals), never a traceback; a failure is one ``error:`` line
  and every other stderr line is a one-line ``warning:``;
- nothing is created outside the case's output path; a failed or interrupted run leaves
  the case directory byte for byte as it was (no temporary, lock or partial file).

The classes are the items of the first fuzz's report (``CLASSES``). Cases whose fix belongs to another
change carry ``owner`` (the helper/issue item that fixes it): they are reported, and
now strict: every owner's fix is merged, so each case fails the suite again if it regresses.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import shutil
import stat
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "docs" / "examples"
MODELS = ROOT / "tests" / "data" / "models"

CLASSES = {
    "traversal": "1 names from data become file names only as safe slugs",
    "codegen": "2 nothing data-derived is executable in generated C",
    "memory": "3 huge or binary inputs fail fast with bounded memory",
    "out-target": "4 outputs replace only regular files (devices, FIFOs refused)",
    "non-finite": "5 NaN/Infinity/1e308 never become an output",
    "half-written": "6 nothing half-written: bad input, interruption, disk full, concurrency",
    "exit-code": "7 bad input is exit 2 with one line, never exit 1",
    "hang": "8 size arguments cannot make a run endless",
    "smaller": "9 duplicated headers, BOMs, missing models, rate 0, raw warnings",
}


# ------------------------------------------------------------------ running the CLI

@dataclass
class Outcome:
    code: int
    stdout: str
    stderr: str


def run_inprocess(argv: list[str], cwd: Path | None = None) -> Outcome:
    """Run ``inertialab ARGV`` in this process (fast: imports are shared); an argv
    ``["__python__", SCRIPT]`` runs a Python script instead (library-level cases)."""
    from inertialab.cli.main import main

    if argv and argv[0] == "__python__":
        import runpy

        def main(_args):
            runpy.run_path(argv[1])

    out, err = io.StringIO(), io.StringIO()
    old = os.getcwd()
    try:
        if cwd is not None:
            os.chdir(cwd)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                main([str(a) for a in argv])
                code = 0
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else 1
    finally:
        os.chdir(old)
    return Outcome(code, out.getvalue(), err.getvalue())


def run_subprocess(argv: list[str], cwd: Path | None = None, timeout: float = 120,
                   limit_as: int | None = None) -> Outcome:
    """Run ``python -m inertialab ARGV`` in a fresh process (memory limit in bytes)."""
    def pre():
        if limit_as:
            import resource

            resource.setrlimit(resource.RLIMIT_AS, (limit_as, limit_as))

    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
    try:
        p = subprocess.run([sys.executable, "-m", "inertialab", *map(str, argv)], cwd=cwd,
                           capture_output=True, text=True, timeout=timeout, env=env,
                           preexec_fn=pre)
    except subprocess.TimeoutExpired:
        return Outcome(-9, "", f"timeout after {timeout} s")
    return Outcome(p.returncode, p.stdout, p.stderr)


_DISCOVERED: set[str] | None = None


def discover() -> set[str]:
    """Every visible command, from ``inertialab --help`` and each group's ``--help``."""
    global _DISCOVERED
    if _DISCOVERED is not None:
        return _DISCOVERED

    def commands(prefix: list[str]) -> list[str]:
        text = run_inprocess([*prefix, "--help"]).stdout
        if "Commands:" not in text:
            return []
        block = text.split("Commands:", 1)[1]
        return [m.group(1) for m in re.finditer(r"^  (\S+)", block, re.M)]

    found = set()
    for name in commands([]):
        subs = commands([name])
        if subs:
            found |= {f"{name} {s}" for s in subs}
        else:
            found.add(name)
    _DISCOVERED = found
    return found


def resolve(*spellings: str) -> str:
    """The first of ``spellings`` the CLI shows (newest first); else the first that
    answers ``--help`` (a hidden alias); else the first."""
    known = discover()
    for s in spellings:
        if s in known:
            return s
    for s in spellings:
        if run_inprocess([*s.split(), "--help"]).code == 0:
            return s
    return spellings[0]


# ------------------------------------------------------------------ invariants

def snapshot(root: Path) -> dict[str, object]:
    """Every entry under ``root``: bytes of regular files (size, mtime and inode above
    1 MiB), kind of the others."""
    out: dict[str, object] = {}
    for dirpath, dirs, files in os.walk(root):
        for name in dirs + files:
            p = os.path.join(dirpath, name)
            rel = os.path.relpath(p, root)
            st = os.lstat(p)
            if stat.S_ISREG(st.st_mode) and st.st_size > 1 << 20:  # big: no reading
                out[rel] = (st.st_size, st.st_mtime_ns, st.st_ino)
            elif stat.S_ISREG(st.st_mode):
                with open(p, "rb") as fh:
                    out[rel] = fh.read()
            else:
                out[rel] = stat.S_IFMT(st.st_mode)
    return out


def violations(o: Outcome, before: dict, after: dict, allowed: list[str],
               codes=(0, 2)) -> list[str]:
    """What breaks the issue's invariants in outcome ``o`` (empty list: none)."""
    bad = []
    if "Traceback" in o.stderr:
        bad.append("traceback on stderr")
    if o.code not in codes:
        bad.append(f"exit {o.code}: {o.stderr.strip()[-200:]}")
    lines = [ln for ln in o.stderr.splitlines() if ln.strip()]
    if o.code != 0:
        errors = [ln for ln in lines if ln.startswith("error:")]
        if len(errors) != 1:
            bad.append(f"{len(errors)} error lines")
    for ln in lines:
        if not ln.startswith(("error:", "warning:")) and "\r" not in ln:
            bad.append(f"stray stderr line: {ln[:120]}")
            break
    # a signal after the outputs were committed (inertialab.signals: 128 + signal and
    # this line) ends a run that had finished: its complete outputs are not a failed
    # run's changes (a late SIGTERM met that window once in CI under load)
    finished = "after the outputs were complete" in o.stderr
    if o.code != 0 and not finished:
        if after != before:
            changed = sorted(set(after) ^ set(before)) or sorted(
                k for k in after if after[k] != before.get(k))
            bad.append(f"failed run changed the filesystem: {changed[:5]}")
    else:
        for rel in set(after) - set(before):
            if not any(rel == a or rel.startswith(a + os.sep) for a in allowed):
                bad.append(f"created outside the output: {rel}")
                break
        for rel in after:
            base = os.path.basename(rel)
            if base.endswith(".tmp") or ".inertialab-tmp-" in base or \
                    base.endswith(".inertialab-lock"):
                bad.append(f"temporary left behind: {rel}")
                break
    return bad


def names_its_file(o: Outcome, argv: list[str], d: Path, before: dict) -> list[str]:
    """A run that failed on its input files prints one error line naming a file: the
    case directory's path, or the name of a file given on the command line. A line that
    starts with an option (``error: --order must be ...``) is an argument error and names
    the option instead. Runs without an input file on the command line are not judged."""
    if o.code in (0, 130, 143):
        return []
    names = {" ".join(os.path.basename(a.rstrip(os.sep)).split()) for a in argv
             if a and not a.startswith("-") and (os.sep in a or a in before or
                                                 re.search(r"\.[A-Za-z]\w*$", a))}
    names.discard("")
    if not any(os.path.lexists(a) for a in argv if a and not a.startswith("-")):
        return []
    errors = [ln for ln in o.stderr.splitlines() if ln.startswith("error:")]
    if not errors:
        return []  # counted by violations()
    line = errors[0]
    if line.startswith("error: -") or str(d) in line or any(n in line for n in names):
        return []
    return [f"error line names no file: {line[:160]}"]


# ------------------------------------------------------------------ cases

@dataclass
class Case:
    """One hostile run. ``setup(d)`` writes the case's inputs into directory ``d`` and
    returns the argv (paths inside ``d``); ``allowed`` are the outputs it may create
    (relative to ``d``); ``codes`` the acceptable exit statuses."""

    cls: str
    command: str
    label: str
    setup: Callable[[Path], list[str]]
    allowed: list[str] = field(default_factory=lambda: ["out", "out.csv", "out.meta.json"])
    codes: tuple[int, ...] = (0, 2)
    expect_code: int | None = None
    owner: str | None = None
    check: Callable[[Path, Outcome], list[str]] | None = None
    slow: bool = False
    runner: Callable[[list[str], Path], Outcome] | None = None
    teardown: Callable[[Path], None] | None = None
    #: a run longer than this (seconds) breaks the case ("fail fast", "no hang")
    max_wall_s: float | None = None

    @property
    def id(self) -> str:
        return f"{self.cls}:{self.command.replace(' ', '-')}:{self.label}"


def run_case(case: Case, d: Path, runner=run_inprocess) -> tuple[Outcome, list[str]]:
    """Set up ``case`` in ``d``, run it, return the outcome and its violations."""
    d.mkdir(parents=True, exist_ok=True)
    try:
        argv = case.setup(d)
        before = snapshot(d)
        t0 = time.monotonic()
        o = (case.runner or runner)(argv, d)
        wall = time.monotonic() - t0
        after = snapshot(d)
    finally:
        if case.teardown is not None:
            case.teardown(d)
    bad = violations(o, before, after, case.allowed, case.codes)
    bad += names_its_file(o, [str(a) for a in argv], d, before)
    if case.expect_code is not None and o.code != case.expect_code:
        bad.append(f"expected exit {case.expect_code}, got {o.code}: {o.stderr.strip()[:200]}")
    if case.check is not None:
        bad += case.check(d, o)
    if case.max_wall_s is not None and wall > case.max_wall_s:
        bad.append(f"took {wall:.0f} s (at most {case.max_wall_s:g} s)")
    return o, bad


def _copy(src: Path, d: Path, name: str | None = None) -> Path:
    dst = d / (name or src.name)
    shutil.copy(src, dst)
    return dst


def _model(kind: str, d: Path, edit=None, text_edit=None) -> Path:
    """A copy of the model fixture of ``kind`` in ``d`` (payload edited by ``edit``)."""
    src = MODELS / f"{kind}-v1.json"
    env = json.loads(src.read_text())
    if edit is not None:
        edit(env["payload"])
    text = json.dumps(env)
    if text_edit is not None:
        text = text_edit(text)
    p = d / "model.json"
    p.write_text(text)
    return p


#: Recipes: role -> (spellings newest first, argv builder(d, inputs) with the main
#: input file path, output kind "dir" | "file" | None, the record it reads)
def _recipes():
    return {
        "allan": (("allan",), lambda d, f: [f, "--out", d / "out"], "dir",
                  EXAMPLES / "gyro_log.csv"),
        "validate": (("validate",), lambda d, f: [f, "--kind", "gyro_log"], None,
                     EXAMPLES / "gyro_log.csv"),
        "thermal fit": (("thermal fit",), lambda d, f: [
            f, "--method", "poly-2d", "--out", d / "out"], "dir",
            EXAMPLES / "thermal_tumble.csv"),
        "thermal apply": (("thermal apply", "thermal compensate"), lambda d, f: [
            _model("thermal-compensation", d), f, "--out", d / "out.csv"], "file",
            EXAMPLES / "thermal_tumble.csv"),
        "triaxial fit": (("triaxial fit", "calibrate triaxial"), lambda d, f: [
            f, "--method", "lm", "--out", d / "out"], "dir", EXAMPLES / "triaxial.static.csv"),
        "triaxial apply": (("triaxial apply", "calibrate apply"), lambda d, f: [
            _model("triaxial-calibration", d), f, "--out", d / "out.csv"], "file",
            EXAMPLES / "triaxial.raw.csv"),
        "dual fit": (("dual fit", "calibrate dual"), lambda d, f: [
            f, "--method", "ls", "--out", d / "out"], "dir", EXAMPLES / "dual_tumble.csv"),
        "drift fit": (("drift fit",), lambda d, f: [
            f, "--quantity", "bias", "--order", "1", "--restarts", "1", "--horizon", "5",
            "--out", d / "out"], "dir", EXAMPLES / "storage_drift.csv"),
        "drift apply": (("drift apply",), lambda d, f: [
            _model("storage-drift", d), f, "--out", d / "out.csv"], "file",
            EXAMPLES / "storage_drift.csv"),
        "vibration apply": (("vibration apply", "vibration-compensate"), lambda d, f: [
            _model("vibration-compensation", d), f, "--out", d / "out.csv"], "file",
            EXAMPLES / "gyro_log.csv"),
        "batch": (("batch",), lambda d, f: [
            "allan", "--inputs", f, "--scheduler", "serial", "--out", d / "out"], "dir",
            EXAMPLES / "gyro_log.csv"),
    }


def argv_for(role: str, d: Path, f) -> list[str]:
    spellings, build, _kind, _src = _recipes()[role]
    return [*resolve(*spellings).split(), *map(str, build(d, f))]


def _finite_output(d: Path, o: Outcome) -> list[str]:
    """A written output record holds no non-finite value in a column the input lacked."""
    out = d / "out.csv"
    if o.code != 0 or not out.exists():
        return []
    import numpy as np
    import pandas as pd

    df = pd.read_csv(out)
    inputs = [p for p in d.iterdir() if p.suffix == ".csv" and p.name != "out.csv"]
    known = set(pd.read_csv(inputs[0], comment="#", nrows=1).columns) if inputs else set()
    bad = [c for c in df.columns if c not in known and df[c].dtype.kind == "f"
           and not np.isfinite(df[c].to_numpy()).all()]
    return [f"non-finite values written in {bad}"] if bad else []


def _input_case(cls, role, label, data: bytes | Callable[[bytes], bytes], *, owner=None,
                name=None, codes=(0, 2), expect=None, sidecar=True) -> Case:
    spellings, _b, _kind, src = _recipes()[role]

    def setup(d: Path) -> list[str]:
        raw = data(src.read_bytes()) if callable(data) else data
        f = d / (name or src.name)
        f.write_bytes(raw)
        side = src.with_name(src.name.split(".")[0] + ".meta.json")
        if sidecar and side.exists():
            shutil.copy(side, d / (f.name.split(".")[0] + ".meta.json"))
        return argv_for(role, d, f)

    return Case(cls, resolve(*spellings), label, setup, owner=owner, codes=codes,
                expect_code=expect, check=_finite_output)


def _cell(raw: bytes, value: str, column: str | None = None) -> bytes:
    """Replace one data cell (row 3, the named or first numeric column) by ``value``."""
    lines = raw.decode("utf-8").splitlines(keepends=True)
    h = next(i for i, ln in enumerate(lines) if not ln.startswith("#"))
    header = lines[h].rstrip("\n").split(",")
    c = header.index(column) if column in header else next(
        (i for i, name in enumerate(header) if name.endswith(("_mv", "_dph", "_mps2", "_ug",
                                                               "_c", "_rps", "_v"))), 1)
    r = min(h + 3, len(lines) - 1)
    cells = lines[r].rstrip("\n").split(",")
    cells[c] = value
    lines[r] = ",".join(cells) + "\n"
    return "".join(lines).encode("utf-8")


def _out_target_cases() -> list[Case]:
    """Item 4: each command with an output, the output pointed at a FIFO, a device link,
    /dev/null itself, and (single-file outputs) an existing directory."""
    cases = []
    for role, (spellings, _b, kind, src) in _recipes().items():
        if kind is None:
            continue
        cmd = resolve(*spellings)
        for label in ("fifo", "device-link", "dev-null", "wrong-kind"):
            def setup(d, role=role, label=label, kind=kind, src=src):
                f = _copy(src, d)
                side = src.with_name(src.name.split(".")[0] + ".meta.json")
                if side.exists():
                    shutil.copy(side, d / side.name)
                target = d / ("out" if kind == "dir" else "out.csv")
                if label == "fifo":
                    os.mkfifo(target)
                elif label == "device-link":
                    os.symlink("/dev/null", target)
                elif label == "wrong-kind":
                    if kind == "dir":
                        target.write_text("keep me\n")
                    else:
                        target.mkdir()
                        (target / "keep.txt").write_text("keep me\n")
                argv = argv_for(role, d, f)
                if label == "dev-null":
                    argv[argv.index("--out") + 1] = "/dev/null"
                return argv

            cases.append(Case("out-target", cmd, label, setup, expect_code=2, allowed=[]))
    return cases


def _half_written_cases() -> list[Case]:
    """Item 6: bad input (empty, garbage, truncated) for every command with an output:
    exit 2 and the output never created."""
    cases = []
    for role, (_s, _b, kind, _src) in _recipes().items():
        if kind is None:
            continue
        for label, data in [("empty", b""), ("garbage", bytes(range(256)) * 8),
                            ("header-only", lambda raw: raw.split(b"\n", 1)[0] + b"\n"),
                            ("truncated", lambda raw: raw[: len(raw) // 3])]:
            cases.append(_input_case("half-written", role, label, data))
    return cases


def _exit_code_cases() -> list[Case]:
    """Item 7: bad sizes, directories as files, deep/huge JSON and TOML, bad encodings."""
    cases = []
    size_args = [("allan", ["--rate", "1e308"]), ("allan", ["--rate", "1e-308"]),
                 ("allan", ["--taus", "1e11"]), ("validate", ["--rate", "0"])]
    for role, extra in size_args:
        spellings, _b, _k, src = _recipes()[role]

        def setup(d, role=role, extra=extra, src=src):
            return [*argv_for(role, d, _copy(src, d)), *extra]

        cases.append(Case("exit-code", resolve(*spellings), " ".join(extra), setup,
                          expect_code=2))
    dual_design = resolve("dual design", "design dual")
    cases.append(Case("exit-code", dual_design, "--positions 1e8",
                      lambda d: [*dual_design.split(), "--positions", "100000000"],
                      expect_code=2))
    for role in ("thermal apply", "triaxial apply", "vibration apply"):
        spellings, _b, _k, src = _recipes()[role]
        for label in ("model-is-dir", "model-nested-1000", "model-5000-digit-int",
                      "model-latin1", "model-utf16"):
            def setup(d, role=role, label=label, src=src):
                argv = argv_for(role, d, _copy(src, d))
                m = d / "model.json"
                m.unlink()
                if label == "model-is-dir":
                    m.mkdir()
                elif label == "model-nested-1000":
                    m.write_text('{"format": "inertialab-model", "x": ' + "[" * 1000 +
                                 "]" * 1000 + "}")
                elif label == "model-5000-digit-int":
                    m.write_text('{"format": "inertialab-model", "format_version": ' +
                                 "9" * 5000 + "}")
                elif label == "model-latin1":
                    m.write_bytes('{"format": "inertialab-model", "unit": "°"}'.encode("latin-1"))
                else:
                    m.write_bytes('{"format": "inertialab-model"}'.encode("utf-16"))
                return argv

            cases.append(Case("exit-code", resolve(*spellings), label, setup, expect_code=2,
                              allowed=["model.json"]))
    for label, text in [("config-nested-1000", "a = " + "[" * 1000 + "]" * 1000 + "\n"),
                        ("config-5000-digit-int", "a = " + "9" * 5000 + "\n"),
                        ("config-binary", "\x00\xff\xfe garbage")]:
        def setup(d, text=text):
            (d / "run.toml").write_bytes(text.encode("utf-8", "surrogateescape"))
            return ["--config", str(d / "run.toml")]

        cases.append(Case("exit-code", "--config", label, setup, expect_code=2))
    return cases


def _non_finite_cases() -> list[Case]:
    """Item 5: non-finite tokens in model files, 1e308 cells in inputs."""
    cases = []
    for role, kind in [("thermal apply", "thermal-compensation"),
                       ("triaxial apply", "triaxial-calibration"),
                       ("vibration apply", "vibration-compensation")]:
        spellings, _b, _k, src = _recipes()[role]
        for token in ("NaN", "Infinity", "-Infinity", "1e999"):
            def setup(d, role=role, token=token, kind=kind, src=src):
                argv = argv_for(role, d, _copy(src, d))

                def edit(payload):
                    _set_first_number(payload, 4242.25)

                _model(kind, d, edit=edit,
                       text_edit=lambda t: t.replace("4242.25", token, 1))
                return argv

            cases.append(Case("non-finite", resolve(*spellings), f"model-{token}", setup,
                              expect_code=2, allowed=["model.json"]))
    drift_fc = resolve("drift forecast")
    for token in ("NaN", "Infinity"):
        def setup(d, token=token):
            m = _model("storage-drift", d, edit=lambda p: _set_first_number(p, 4242.25),
                       text_edit=lambda t: t.replace("4242.25", token, 1))
            return [*drift_fc.split(), str(m), "--json"]

        cases.append(Case("non-finite", drift_fc, f"model-{token}", setup, expect_code=2,
                          allowed=["model.json"]))
    for role, column in [("thermal apply", "output_mv"), ("triaxial apply", None),
                         ("validate", None), ("allan", None)]:
        for value in ("1e308", "-1e308", "nan", "inf"):
            cases.append(_input_case(
                "non-finite", role, f"cell-{value}", lambda raw, v=value, c=column: _cell(raw, v, c),
                owner=None if role == "validate" else "the study's workflow: ensure_finite "
                "on its result"))
    return cases


def _set_first_number(obj, value) -> bool:
    """Set the first float leaf (depth first) of ``obj`` to ``value``."""
    items = obj.items() if isinstance(obj, dict) else enumerate(obj)
    for k, v in items:
        if isinstance(v, float):
            obj[k] = value
            return True
        if isinstance(v, (dict, list)) and _set_first_number(v, value):
            return True
    return False


def _codegen_cases() -> list[Case]:
    """Item 2: a unit_id that closes the C comment; non-finite coefficients."""
    export = resolve("thermal export")

    def inject(payload):
        payload["unit_id"] = "U */ int evil(void){return 1;} /*"

    def setup(d):
        m = _model("thermal-compensation", d, edit=inject)
        return [*export.split(), str(m), "--c", str(d / "out")]

    def no_symbol(d, o):
        bad = []
        for p in (d / "out").glob("*.[ch]") if (d / "out").is_dir() else []:
            code = re.sub(r"/\*.*?\*/", "", p.read_text(), flags=re.S)
            code = re.sub(r"//[^\n]*", "", code)
            if "evil" in code:
                bad.append(f"data-derived text compiles into code in {p.name}")
        return bad

    return [Case("codegen", export, "comment-injection", setup, allowed=["out", "model.json"],
                 check=no_symbol, owner="thermal helper")]


def _traversal_cases() -> list[Case]:
    """Item 1 at the shared layer: a figure name taken from data cannot leave --out."""
    def check(d, o):
        return [f"escaped: {p}" for p in d.parent.glob("ESCAPED*")] + \
            [f"escaped: {p}" for p in d.glob("ESCAPED*")]

    def setup(d):
        script = ("import matplotlib; matplotlib.use('Agg');"
                  "import matplotlib.pyplot as plt;"
                  "from inertialab.io.outputs import transaction, stage_dir;"
                  "from inertialab.cli.common import write_figures;"
                  f"exec(\"with transaction():\\n write_figures([('x/../../../ESCAPED', "
                  f"plt.figure()), ('U'*300, plt.figure())], stage_dir(r'{d / 'out'}'))\")")
        (d / "t.py").write_text(script)
        return ["__python__", str(d / "t.py")]

    return [Case("traversal", "write_figures", "unit_id-traversal", setup, check=check,
                 allowed=["out", "t.py"])]


def _hang_cases() -> list[Case]:
    fc = resolve("drift forecast")
    return [Case("hang", fc, "--horizon 100000000",
                 lambda d: [*fc.split(), str(_model("storage-drift", d)), "--horizon",
                            "100000000", "--json"], expect_code=2, allowed=["model.json"])]


def _smaller_cases() -> list[Case]:
    cases = [_input_case("smaller", "validate", "duplicated-header",
                         lambda raw: _dup_header(raw), expect=2,
                         owner="io helper"),
             _input_case("smaller", "triaxial apply", "utf8-bom-raw-log",
                         lambda raw: b"\xef\xbb\xbf" + raw,
                         owner="io helper")]
    imu = resolve("allan-imu", "allan")
    cases.append(Case("smaller", imu, "--rate 0", lambda d: [
        *imu.split(), str(_copy(EXAMPLES / "vendors" / "vectornav.csv", d)), "--rate", "0"]
        + (["--imu"] if imu == "allan" else []), expect_code=2))
    batch = resolve("batch")
    cases.append(Case("smaller", batch, "missing-model", lambda d: [
        "batch", "thermal", "compensate", "--inputs", str(_copy(EXAMPLES / "thermal_tumble.csv",
                                                                 d)),
        "--model", str(d / "nonexist.json"), "--scheduler", "serial"], expect_code=2,
        owner="io helper"))
    return cases


def _dup_header(raw: bytes) -> bytes:
    lines = raw.decode("utf-8").splitlines(keepends=True)
    h = next(i for i, ln in enumerate(lines) if not ln.startswith("#"))
    cols = lines[h].rstrip("\n").split(",")
    cols[-1] = cols[1]
    lines[h] = ",".join(cols) + "\n"
    return "".join(lines).encode("utf-8")


def fast_cases() -> list[Case]:
    """The cases of the normal test run (seconds each, in-process)."""
    return (_traversal_cases() + _codegen_cases() + _out_target_cases() +
            _non_finite_cases() + _half_written_cases() + _exit_code_cases() +
            _hang_cases() + _smaller_cases() + _fourth_fast())


# ------------------------------------------------------------------ the slow set

def _interrupt(signum: int, after_s: float):
    """A runner: start the command in a subprocess, send ``signum`` after ``after_s``."""
    import signal as _signal
    import time

    def runner(argv, cwd):
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
        p = subprocess.Popen([sys.executable, "-m", "inertialab", *map(str, argv)], cwd=cwd,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and p.poll() is None and not _catches(p.pid, 15):
            time.sleep(0.1)  # the CLI's handler is installed: the run has started
        time.sleep(after_s)
        p.send_signal(signum)
        try:
            out, err = p.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            p.kill()
            out, err = p.communicate()
            return Outcome(-9, out, err + "did not stop within 60 s of the signal")
        if p.returncode == 0:  # finished before the signal: not an interruption case
            return Outcome(0, out, err)
        return Outcome(p.returncode, out, err)

    runner.signum = _signal.Signals(signum).name
    return runner


def _catches(pid: int, signum: int) -> bool:
    """Whether process ``pid`` has a handler for ``signum`` (Linux /proc SigCgt)."""
    try:
        with open(f"/proc/{pid}/status") as fh:
            for line in fh:
                if line.startswith("SigCgt:"):
                    return bool(int(line.split()[1], 16) >> (signum - 1) & 1)
    except OSError:
        return True  # no /proc: fall back on the delay alone
    return False


def _concurrent(argv, cwd) -> Outcome:
    """Two identical runs into one output at the same time."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
    procs = [subprocess.Popen([sys.executable, "-m", "inertialab", *map(str, argv)], cwd=cwd,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
             for _ in range(2)]
    res = [p.communicate(timeout=300) for p in procs]
    codes = [p.returncode for p in procs]
    # the pair is fine when both ended in 0/2 and at least one succeeded
    code = 0 if 0 in codes and set(codes) <= {0, 2} else max(codes)
    err = "".join(r[1] for r, c in zip(res, codes, strict=True) if c != 0 or code != 0)
    return Outcome(code, res[0][0], err if code else "")


def _mount_tmpfs(where: Path, size: str, ro: bool = False) -> bool:
    where.mkdir(exist_ok=True)
    opts = f"size={size}" + (",ro" if ro else "")
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", opts, "tmpfs", str(where)],
                       capture_output=True)
    return r.returncode == 0


def _umount(d: Path) -> None:
    for name in ("full", "ro"):
        if (d / name).is_mount():
            subprocess.run(["umount", "-l", str(d / name)], capture_output=True)


def tmpfs_available(tmp: Path) -> bool:
    """Whether this machine lets us mount a small tmpfs (root, no container veto)."""
    probe = tmp / "probe"
    ok = _mount_tmpfs(probe, "16k")
    if ok:
        subprocess.run(["umount", str(probe)], capture_output=True)
    return ok


def _sim(kind_argv: list[str]):
    """Setup writing a virtual-lab record first (subprocess), then the command."""
    def make(d: Path, then: list[str]) -> list[str]:
        o = run_subprocess(kind_argv, cwd=d)
        if o.code != 0:
            raise RuntimeError(f"simulate failed: {o.stderr}")
        return then
    return make


def slow_cases() -> list[Case]:
    """Subprocess cases: 2 GB sparse file, disk full and read-only (tmpfs), SIGTERM and
    SIGINT mid-run, two concurrent writers, a re-used folder, names from data, horizon."""
    import signal as _signal

    cases = []
    for role in ("validate", "allan", "triaxial fit"):
        spellings, _b, _k, src = _recipes()[role]

        def setup(d, role=role, src=src):
            f = d / src.name
            with open(f, "wb") as fh:
                fh.write(src.read_bytes()[:200])
                fh.truncate(2 << 30)  # 2 GiB, sparse: zeros after a real header
            return argv_for(role, d, f)

        cases.append(Case("memory", resolve(*spellings), "2GB-sparse", setup, slow=True,
                          expect_code=2, owner="io helper", max_wall_s=20,
                          runner=_watchdog))
    tfit = resolve("thermal fit")
    tapply = resolve("thermal apply", "thermal compensate")
    th = EXAMPLES / "thermal_tumble.csv"

    def full_dir(d):
        if not _mount_tmpfs(d / "full", "48k"):
            raise _Skip("cannot mount tmpfs here")
        return [*tfit.split(), str(_copy(th, d)), "--method", "poly-2d", "--out",
                str(d / "full" / "out")]

    def full_file(d):
        if not _mount_tmpfs(d / "full", "48k"):
            raise _Skip("cannot mount tmpfs here")
        return ["simulate", "gyro-static", "--preset", "allan-test", "--hours", "0.5",
                "--rate", "100", "--out", str(d / "full" / "out.csv")]

    def read_only(d):
        if not _mount_tmpfs(d / "ro", "1m", ro=True):
            raise _Skip("cannot mount tmpfs here")
        return [*tapply.split(), str(_model("thermal-compensation", d)), str(_copy(th, d)),
                "--out", str(d / "ro" / "out.csv")]

    for label, setup in [("disk-full-dir", full_dir), ("disk-full-file", full_file),
                         ("read-only", read_only)]:
        cases.append(Case("half-written" if "full" in label else "exit-code",
                          {"disk-full-dir": tfit, "disk-full-file": "simulate gyro-static"}.get(
                              label, tapply), label, setup,
                          slow=True, expect_code=2, teardown=_umount,
                          runner=lambda a, c: run_subprocess(a, c, timeout=120)))
    for signum, code in ((_signal.SIGTERM, 143), (_signal.SIGINT, 130)):
        name = _signal.Signals(signum).name

        def sig_dir(d):
            return [*tfit.split(), str(_copy(th, d)), "--out", str(d / "out"), "--quiet"]

        def sig_reused(d):
            argv = sig_dir(d)
            (d / "out").mkdir()
            (d / "out" / "_inertialab").write_text("{}")
            (d / "out" / "model.json").write_text("{\"old\": true}")
            return argv

        def sig_file(d):
            return ["simulate", "gyro-static", "--preset", "allan-test", "--hours", "10",
                    "--rate", "100", "--out", str(d / "out.csv")]

        for label, setup in (("dir", sig_dir), ("reused-dir", sig_reused), ("file", sig_file)):
            cases.append(Case("half-written", tfit if "dir" in label else "simulate gyro-static",
                              f"{name}-{label}", setup, slow=True, codes=(code,),
                              expect_code=code, runner=_interrupt(signum, 3.0)))

    def concurrent(d):
        return [*tfit.split(), str(_copy(th, d)), "--method", "poly-2d", "--out",
                str(d / "out"), "--quiet"]

    def complete(d, o):
        files = sorted(p.name for p in (d / "out").iterdir()) if (d / "out").is_dir() else []
        need = {"model.json", "result.json", "_inertialab"}
        return [] if need <= set(files) else [f"output incomplete: {files}"]

    cases.append(Case("half-written", tfit, "two-concurrent-writers", concurrent, slow=True,
                      runner=_concurrent, check=complete))

    def stale(d):
        argv = concurrent(d)
        (d / "out" / "models").mkdir(parents=True)
        (d / "out" / "_inertialab").write_text("{}")
        (d / "out" / "models" / "stale.json").write_text("{}")
        return argv

    def no_stale(d, o):
        return ["stale models/stale.json kept"] if (d / "out/models/stale.json").exists() else []

    cases.append(Case("half-written", tfit, "reused-folder-replaced-whole", stale, slow=True,
                      check=no_stale, runner=lambda a, c: run_subprocess(a, c, timeout=300)))

    dfit = resolve("drift fit")

    def traversal(d):
        o = run_subprocess(["simulate", "storage-drift", "--units", "2", "--days", "40",
                            "--out", str(d / "drift.csv")], cwd=d)
        if o.code != 0:
            raise RuntimeError(o.stderr)
        text = (d / "drift.csv").read_text()
        ids = sorted(set(re.findall(r"^[^,\n]*?,?(QA\d+)", text, re.M)))
        if len(ids) >= 2:
            text = text.replace(ids[0], "x/../../../ESCAPED").replace(ids[1], "U" * 300)
        (d / "drift.csv").write_text(text)
        return [*dfit.split(), str(d / "drift.csv"), "--quantity", "bias", "--order", "1",
                "--restarts", "1", "--horizon", "5", "--out", str(d / "out")]

    def escaped(d, o):
        return [f"escaped: {p}" for p in list(d.parent.rglob("ESCAPED*"))]

    cases.append(Case("traversal", dfit, "unit_id-traversal-and-300-chars", traversal,
                      slow=True, check=escaped, owner="drift helper",
                      allowed=["out", "drift.csv", "drift.meta.json"],
                      runner=lambda a, c: run_subprocess(a, c, timeout=300)))
    fc = resolve("drift forecast")
    cases.append(Case("hang", fc, "--horizon 36500", lambda d: [
        *fc.split(), str(_model("storage-drift", d)), "--horizon", "36500", "--json"],
        slow=True, owner="drift helper", allowed=["model.json"],
        max_wall_s=30,
        runner=lambda a, c: run_subprocess(a, c, timeout=60)))
    return cases + _fourth_slow()


def _watchdog(argv, cwd) -> Outcome:
    """A subprocess run without an address-space limit, failed by the watchdog of
    :func:`tests.fuzz.second_round.watched` over 2 GB resident or 60 s."""
    from tests.fuzz.second_round import watched

    return watched(argv, cwd)


class _Skip(Exception):
    """A case this machine cannot run (e.g. no tmpfs mount): skipped, with the reason."""


# ------------------------------------------------------------------ options, models, sidecars,
# outputs, big bad files and clock seams (the fourth fuzz, generated data)

CLASSES.update({
    "options": "10 options bounded and checked before any work, naming the option",
    "models": "11 models re-checked on apply; every payload field typed; keys once",
    "sidecars": "12 sidecars typed and agreeing with the columns and the time stamps",
    "outputs": "13 outputs: no overlap, one writer at a time, a late signal gets its line",
    "bad-cell": "14 a bad cell at the end of a big file costs no more memory than none",
    "clock": "15 clock seams: one-series files, a fixed noise type",
})


def _says(*needles):
    """A check: stderr holds every one of ``needles``."""
    def check(d, o):
        return [] if all(n in o.stderr for n in needles) else \
            [f"stderr lacks {needles!r}: {o.stderr.strip()[-200:]}"]
    return check


def _imu_log(d: Path, name: str = "imu.csv", seconds: float = 60.0, fs: float = 100.0,
             seed: int = 0) -> Path:
    """A six-axis IMU log at rest (white noise, gravity on z), seeded."""
    import numpy as np

    rng = np.random.default_rng(seed)
    n = int(seconds * fs)
    g = rng.normal(0.0, 0.01, (n, 3))
    a = rng.normal(0.0, 0.002, (n, 3))
    a[:, 2] += 9.81
    f = d / name
    with open(f, "w") as fh:
        fh.write("t_s,gx_rps,gy_rps,gz_rps,ax_mps2,ay_mps2,az_mps2\n")
        np.savetxt(fh, np.column_stack([np.arange(n) / fs, g, a]), delimiter=",",
                   fmt="%.6f")
    return f


def _imu_case(cls, label, extra, *, expect=2, needles=(), check=None, allowed=(),
              max_wall_s=None) -> Case:
    """``allan FILE --imu EXTRA`` on a generated 60-s log (``{f}``, ``{d}`` and
    ``{check}``, a 15-s log of the same sensor, are filled in)."""
    def setup(d, extra=extra):
        f = _imu_log(d)
        chk = _imu_log(d, "check.csv", seconds=15.0, seed=1)
        return ["allan", str(f), "--imu", "--quiet",
                *[a.format(f=f, d=d, check=chk) for a in extra]]

    checks = [c for c in (_says(*needles) if needles else None, check) if c is not None]
    return Case(cls, "allan --imu", label, setup, expect_code=expect,
                allowed=["imu.csv", "check.csv", *allowed], max_wall_s=max_wall_s,
                check=(lambda d, o: [b for c in checks for b in c(d, o)]) if checks else None)


def _not_inflated(d, o):
    """The export says it is uninflated, and so does a warning of the run (in the JSON
    object: ``--quiet`` keeps warnings off stderr)."""
    import json

    y = d / "imu.yaml"
    if o.code != 0 or not y.exists():
        return ["no imu.yaml written"]
    text = y.read_text()
    bad = [] if "NOT inflated" in text else ["imu.yaml does not say it is uninflated"]
    warned = json.loads(o.stdout)["warnings"]
    return bad + ([] if any("NOT inflated" in w for w in warned) else
                  [f"no warning says NOT inflated: {warned}"])


def _option_cases() -> list[Case]:
    many = ",".join(str(i + 1) for i in range(10_000))
    cases = [
        _imu_case("options", "--predict-drift 10000 horizons", ["--predict-drift", many],
                  needles=("--predict-drift", "10000 horizons"), max_wall_s=30),
        _imu_case("options", "--predict-drift 1e308", ["--predict-drift", "1e308"],
                  needles=("--predict-drift",)),
        _imu_case("options", "--predict-drift 3300x the record", ["--predict-drift", "198000"],
                  needles=("--predict-drift", "longer than the 60 s")),
        _imu_case("options", "--predict-drift duplicated", ["--predict-drift", "10,1,10"],
                  needles=("twice",)),
        _imu_case("options", "--predict-drift empty horizon", ["--predict-drift", "1,,10"],
                  needles=("empty horizon",)),
        _imu_case("options", "--check-on ''", ["--predict-drift", "1", "--check-on", ""],
                  needles=("--check-on is empty",)),
        _imu_case("options", "--check-on the fitted file", ["--predict-drift", "1",
                                                            "--check-on", "{f}"],
                  needles=("analysed log itself",)),
        _imu_case("options", "--rostopic checked before the analysis",
                  ["--export", "kalibr", "{d}/imu.yaml", "--rostopic", "/imu0 x"],
                  needles=("--rostopic",), max_wall_s=20),
        _imu_case("options", "--method checked before the analysis", ["--method", "lsq"],
                  needles=("--method",), max_wall_s=20),
        _imu_case("options", "check without a usable window: warned, export says uninflated",
                  ["--predict-drift", "20", "--check-on", "{check}", "--inflate", "auto",
                   "--export", "kalibr", "{d}/imu.yaml", "--json"], expect=0,
                  check=_not_inflated,
                  allowed=("imu.yaml",)),
    ]
    for label, extra, needle in (("--tolerance adev_1s<=nan", ["--tolerance", "adev_1s<=nan"],
                                  "--tolerance"),
                                 ("--unit ',,'", ["--unit", ",,"], "--unit")):
        def setup(d, extra=extra):
            return ["batch", "allan", "--inputs", str(_copy(EXAMPLES / "gyro_log.csv", d)),
                    "--scheduler", "serial", "--out", str(d / "out"), *extra]
        cases.append(Case("options", "batch", label, setup, expect_code=2,
                          check=_says(needle)))
    return cases


def _model_cases() -> list[Case]:
    th = EXAMPLES / "thermal_tumble.csv"

    def shifted(p):
        p["regressor"]["y_lo"] += 7000.0  # every output 7000 mV (about 7 g) off

    def thermal(edit, force=False):
        def setup(d):
            f = _copy(th, d)
            m = _model("thermal-compensation", d, edit=edit)
            return ["thermal", "apply", str(m), str(f), "--out", str(d / "out.csv"),
                    *(["--force"] if force else [])]
        return setup

    def flagged(d, o):
        meta = d / "out.meta.json"
        if o.code != 0 or not meta.exists():
            return ["forced output not written"]
        return [] if json.loads(meta.read_text()).get("flags") else ["output not flagged"]

    def triaxial(kind, edit=None, text_edit=None):
        def setup(d):
            f = _copy(EXAMPLES / "triaxial.raw.csv", d)
            m = _model(kind, d, edit=edit, text_edit=text_edit)
            return ["triaxial", "apply", str(m), str(f), "--out", str(d / "out.csv")]
        return setup

    def export_x_span(d):
        m = _model("thermal-compensation", d,
                   edit=lambda p: p["regressor"]["x_span"].__setitem__(0, "1.5"))
        return ["thermal", "export", str(m), "--c", str(d / "out")]

    keep = ["model.json", "thermal_tumble.csv", "triaxial.raw.csv"]
    return [
        Case("models", "thermal export", "x_span '1.5'", export_x_span, expect_code=2,
             allowed=keep, check=_says("x_span[0]: must be a number")),
        Case("models", "thermal apply", "outputs shifted 7 g", thermal(shifted),
             expect_code=2, allowed=keep, check=_says("implausible at its training")),
        Case("models", "thermal apply", "outputs shifted 7 g --force", thermal(shifted, True),
             expect_code=0, allowed=[*keep, "out.csv", "out.meta.json"],
             check=lambda d, o: flagged(d, o) + _says("applied anyway")(d, o)),
        Case("models", "triaxial apply", "correction matrix x 1e6", triaxial(
            "triaxial-calibration", edit=lambda p: p.__setitem__(
                "correction_matrix", [[v * 1e6 for v in r] for r in p["correction_matrix"]])),
            expect_code=2, allowed=keep, check=_says("implausible at its training")),
        Case("models", "triaxial apply", "a key given twice", triaxial(
            "triaxial-calibration", text_edit=lambda t: t.replace(
                '"method": "lm",', '"method": "lm", "method": "acs",', 1)),
            expect_code=2, allowed=keep, check=_says("appears twice")),
        Case("models", "triaxial apply", "true as a number", triaxial(
            "triaxial-calibration", edit=lambda p: p.__setitem__("iterations", True)),
            expect_code=2, allowed=keep, check=_says("iterations: must be an integer")),
        Case("models", "triaxial apply", "Ferraris turn axis of 600000", triaxial(
            "ferraris-calibration", edit=lambda p: p["gyro"]["turns"]["x_rot"].__setitem__(
                "axis", [0.0] * 600_000)),
            expect_code=2, allowed=keep, check=_says("must have 3 entries")),
    ]


def _gyro_with_sidecar(side: str, *, stamps_hz: float | None = None, extra=()):
    def setup(d):
        if stamps_hz is None:
            f = _copy(EXAMPLES / "gyro_log.csv", d)
        else:
            f = d / "gyro_log.csv"
            f.write_text("t_s,rate_dph\n" + "".join(
                f"{i / stamps_hz:.9e},{(i * 7919) % 13 / 10:.3f}\n" for i in range(3000)))
        (d / "gyro_log.meta.json").write_text(side)
        return ["validate", str(f), "--kind", "gyro_log", *extra]
    return setup


def _sidecar_cases() -> list[Case]:
    keep = ["gyro_log.csv", "gyro_log.meta.json"]
    rows = [("adc as strings", '{"adc": {"bits": "16", "signed": "no"}}', "adc.bits"),
            ("adc not an object", '{"adc": 16}', "key 'adc' must be an object"),
            ("units over a suffixed column", '{"units": {"rate": "dps"}}',
             "the header says units=dps"),
            ("a key given twice", '{"fs_hz": 200, "fs_hz": 100}', "appears twice"),
            ("true as a number", '{"fs_hz": true}', "key 'fs_hz' must be a number")]
    cases = [Case("sidecars", "validate", label, _gyro_with_sidecar(side), expect_code=2,
                  allowed=keep, check=_says(needle)) for label, side, needle in rows]
    cases.append(Case("sidecars", "validate", "fs_hz 10 vs 1e7-Hz stamps: both named",
                      _gyro_with_sidecar('{"fs_hz": 10}', stamps_hz=1e7), expect_code=2,
                      allowed=keep, check=_says("fs_hz = 10 Hz", "1e+07 Hz")))
    cases.append(Case("sidecars", "validate", "fs_hz 10 vs 1e7-Hz stamps, --rate decides",
                      _gyro_with_sidecar('{"fs_hz": 10}', stamps_hz=1e7,
                                         extra=["--rate", "1e7"]),
                      expect_code=0, allowed=keep))
    return cases


def _output_cases() -> list[Case]:
    def vn(d, export, out):
        for name in ("vectornav.csv", "vectornav.map.json"):
            _copy(EXAMPLES / "vendors" / name, d)
        return ["allan", str(d / "vectornav.csv"), "--imu", "--map-file",
                str(d / "vectornav.map.json"), "--export", "kalibr", str(export), "--out",
                str(out)]

    def stale(d):
        (d / ".out.csv.inertialab-lock").write_text("")  # left by a killed run
        (d / ".out.csv.x1y2z3.tmp").write_text("partial")
        return ["simulate", "gyro-static", "--preset", "allan-test", "--hours", "0.01",
                "--rate", "100", "--out", str(d / "out.csv"), "--quiet"]

    return [
        Case("outputs", "allan --imu", "--export X --out X",
             lambda d: vn(d, d / "X", d / "X"), expect_code=2,
             check=_says("name the same output")),
        Case("outputs", "allan --imu", "--out D --export kalibr D/k.yaml",
             lambda d: vn(d, d / "D" / "k.yaml", d / "D"), expect_code=2,
             check=_says("lies inside --out")),
        Case("outputs", "simulate gyro-static", "a killed run's lock and temporary", stale,
             expect_code=0),
    ]


def _second_writer(argv, cwd) -> Outcome:
    """Two identical runs started together into one output: the one that takes the lock
    first must complete (exit 0) and the other be refused at once (exit 2, "being written
    by another inertialab run"); both exiting 0 (the last writer silently winning) fails.
    Started together, their imports take the same time, so the refusal does not depend
    on how loaded the machine is."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
    procs = [subprocess.Popen([sys.executable, "-m", "inertialab", *map(str, argv)],
                              cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True, env=env) for _ in range(2)]
    res = [p.communicate(timeout=300) for p in procs]
    codes = sorted(p.returncode for p in procs)
    if codes != [0, 2]:
        return Outcome(1, res[0][0], f"exits {codes}: " + " | ".join(
            r[1].strip()[-120:] for r in res))
    loser = next(r for r, p in zip(res, procs) if p.returncode == 2)
    return Outcome(0, res[0][0], "" if "being written by another" in loser[1] else
                   f"refused run's line: {loser[1].strip()[-200:]}")


def _late_signal(after_s: float):
    """A runner: SIGTERM ``after_s`` after the output file appears: exit 0 (done before)
    or 143 with the documented line, never a silent death (-15)."""
    import signal as _signal

    def runner(argv, cwd):
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
        p = subprocess.Popen([sys.executable, "-m", "inertialab", *map(str, argv)], cwd=cwd,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             env=env)
        out = Path(cwd) / "out.csv"
        while p.poll() is None and not out.exists():
            time.sleep(0.001)
        time.sleep(after_s)
        if p.poll() is None:
            p.send_signal(_signal.SIGTERM)
        o, e = p.communicate(timeout=60)
        return Outcome(p.returncode, o, e)
    return runner


def _late_line(d, o):
    if o.code == 143 and "after the outputs were complete" not in o.stderr:
        return ["143 without the documented line"]
    return []


def _fourth_fast() -> list[Case]:
    return _option_cases() + _model_cases() + _sidecar_cases() + _output_cases() + \
        _clock_cases()


def _clock_cases() -> list[Case]:
    def dat(d):
        import numpy as np

        f = d / "clock.dat"  # Stable32's .DAT: one phase value a line, no header
        np.savetxt(f, np.cumsum(np.random.default_rng(5).normal(size=1500)) * 1e-9,
                   fmt="%.12e")
        return f

    def records_type(d, o):
        try:
            s = json.loads(o.stdout)["settings"]
        except (ValueError, KeyError):
            return ["no JSON settings"]
        return [] if s.get("noise_type") == {"totdev": -1} else [f"noise_type {s.get('noise_type')}"]

    base = ["--input", "phase", "--rate", "1", "--unit", "s"]
    return [
        Case("clock", "allan", "one-series .DAT without --column",
             lambda d: ["allan", str(dat(d)), *base, "--quiet"], expect_code=0,
             allowed=["clock.dat"]),
        Case("clock", "allan", "--noise-type totdev=FFM recorded",
             lambda d: ["allan", str(dat(d)), *base, "--stat", "oadev,totdev",
                        "--noise-type", "totdev=FFM", "--json"], expect_code=0,
             allowed=["clock.dat"], check=records_type),
        Case("clock", "allan", "--noise-type 7",
             lambda d: ["allan", str(dat(d)), *base, "--noise-type", "7"], expect_code=2,
             allowed=["clock.dat"], check=_says("--noise-type")),
    ]


def _fourth_slow() -> list[Case]:
    def big_bad(d):
        import numpy as np

        f = d / "big.csv"  # 1.4e7 rows, `abc` as the last rate
        rng = np.random.default_rng(0)
        with open(f, "w") as fh:
            fh.write("t_s,rate_dph\n")
            n, block = 14_000_000, 1_000_000
            for start in range(0, n, block):
                y = rng.normal(0.0, 0.5, block).round(4).tolist()
                lines = [f"{(start + i) / 100:.2f},{v}" for i, v in enumerate(y)]
                if start + block == n:
                    lines[-1] = lines[-1].split(",")[0] + ",abc"
                fh.write("\n".join(lines) + "\n")
        return ["validate", str(f), "--kind", "gyro_log"]

    def tfit(d):  # several seconds of fitting: the second run starts meanwhile
        return ["thermal", "fit", str(_copy(EXAMPLES / "thermal_tumble.csv", d)),
                "--method", "ann,anfis,scm-anfis", "--out", str(d / "out"), "--quiet"]

    def long_sim(d):
        return ["simulate", "gyro-static", "--preset", "allan-test", "--hours", "3",
                "--rate", "100", "--out", str(d / "out.csv"), "--quiet"]

    def sim(d):
        return ["simulate", "gyro-static", "--preset", "allan-test", "--hours", "0.2",
                "--rate", "100", "--out", str(d / "out.csv"), "--quiet"]

    return [
        Case("bad-cell", "validate", "1.4e7 rows, abc last (watched: 2 GB)", big_bad,
             slow=True, expect_code=2, allowed=["big.csv"], runner=_watchdog,
             check=_says("row 14000000", "non-numeric value 'abc'")),
        Case("outputs", "thermal fit", "a second run to the same --out is refused", tfit,
             slow=True, expect_code=0, allowed=["out", "thermal_tumble.csv"],
             runner=_second_writer, check=lambda d, o: [] if {"model.json", "result.json",
                                                              "_inertialab"} <= {
                 p.name for p in (d / "out").glob("*")} else ["the first run's output "
                                                              "is incomplete"]),
        Case("outputs", "simulate gyro-static", "a second run to the same file is refused",
             long_sim, slow=True, expect_code=0, runner=_second_writer),
        *[Case("outputs", "simulate gyro-static", f"SIGTERM {t:g} s after the output",
               sim, slow=True, codes=(0, 143), runner=_late_signal(t), check=_late_line)
          for t in (0.0, 0.2, 0.5)],
    ]
