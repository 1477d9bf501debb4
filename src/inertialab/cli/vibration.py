"""``inertialab vibration fit|apply`` and ``inertialab simulate fog-vibration`` (spec 001).

Thin: parse, call :mod:`inertialab.workflows.vibration` (``fit``, ``apply``) /
:mod:`inertialab.sim.fog_vibration`, print or write. A bare ``inertialab vibration SWEEP
[FIXED]`` is routed to ``vibration fit`` by :mod:`inertialab.cli.main`; the old
``vibration-compensate`` spelling stays as a hidden alias of ``vibration apply``.
"""

# typer reads these signatures (the Annotated shared options of cli.options);
# plain annotations keep that independent of how reading_options evaluates them
import json
from pathlib import Path

import typer

from inertialab.cli.common import (
    atomic_write_text,
    collect_warnings,
    emit_json,
    prepare_out_dir,
    print_table,
    progress_bar,
    write_figures,
)
from inertialab.cli.options import (
    JsonOpt,
    OutDirOpt,
    QuietOpt,
    SeedOpt,
    reading_options,
)
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.jsonable import to_jsonable

_JSON_UNITS = {
    "level": "1", "delta_j": "1", "residual_bias_dph": "deg/h",
    "fit.rbf.train_rmse": "deg/h", "fit.rbf.heldout_rmse": "deg/h",
    "fit.poly.train_rmse": "deg/h", "fit.poly.heldout_rmse": "deg/h",
    "fit.rbf.train_mse": "(deg/h)^2", "fit.poly.train_mse": "(deg/h)^2",
    "fit.rbf.truth_rmse": "deg/h", "fit.poly.truth_rmse": "deg/h",
    "fit.rbf.spread": "Hz", "fit.rbf.goal": "(deg/h)^2", "fit.f_range_hz": "Hz",
}


def _parse_level(level: str):
    v = level.strip().lower()
    if v == "auto":
        return "auto"
    try:
        n = int(v)
    except ValueError:
        raise InputError(f"--level must be an integer 1..9 or 'auto', got '{level}'") from None
    if not 1 <= n <= 9:
        raise InputError(f"--level must be in 1..9 or 'auto', got {n}")
    return n


def _parse_spread(spread: str):
    v = spread.strip().lower()
    if v == "validate":
        return "validate"
    try:
        x = float(v)
    except ValueError:
        raise InputError(f"--spread must be a positive number (Hz) or 'validate', got "
                         f"'{spread}'") from None
    if not x > 0:
        raise InputError(f"--spread must be positive, got {x}")
    return x


def register(app: typer.Typer, groups: dict) -> None:
    simulate = groups["simulate"]
    vib = groups["vibration"]

    @vib.command("fit")
    @reading_options
    def vibration_fit(
        sweep_file: Path = typer.Argument(..., help="Sweep record (E1), gyro_log with vib_on, "
                                                    "vib_freq_hz."),
        fixed_file: Path = typer.Argument(None, help="Fixed-frequency record (E2) to "
                                                     "compensate (optional)."),
        level: str = typer.Option("6", "--level", help="Approximation level L (seed 6) or "
                                                       "'auto' (spec §3.6 rule)."),
        spread: str = typer.Option("1.2", "--spread", help="RBF spread in Hz (seed 1.2), or "
                                   "'validate': the spread with the least held-out RMSE on "
                                   "the even 1-Hz bins (reported)."),
        goal: float = typer.Option(1e-4, "--goal", help="RBF MSE goal, (deg/h)^2 (seed 1e-4)."),
        centers: str = typer.Option("max_error", "--centers",
                                    help="RBF centres: max_error | ols | random_fixed | all."),
        targets: str = typer.Option("bins", "--targets",
                                    help="E1 training pairs: bins (1-Hz bin means) | samples "
                                         "(every 2^L-th sample)."),
        seed: SeedOpt = 0,
        out: OutDirOpt = None,
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
        read: ReadOptions = None,
    ):
        """FOG under vibration: phase-wise Allan terms, db4 separation, RBF bias compensation
        (fit the bias model on the sweep; compensate the fixed run when given)."""
        from inertialab.io import read_record, save_model
        from inertialab.workflows.vibration import VibrationConfig, fit, prepare

        lvl = _parse_level(level)
        spread_v = _parse_spread(spread)
        if out is not None:
            out_dir = prepare_out_dir(out)
        with collect_warnings(quiet=quiet) as warns:
            sweep = prepare(read_record(sweep_file, "gyro_log", options=read))
            fixed = (prepare(read_record(fixed_file, "gyro_log", options=read))
                     if fixed_file is not None else None)
            cfg = VibrationConfig(level=lvl, spread=spread_v, goal=goal, centers=centers,
                                  targets=targets, rng=seed, views=out is not None)
            with progress_bar("vibration", quiet=quiet) as bar:
                res = fit(sweep, fixed, cfg, bar)
            if out is not None:
                from inertialab.calib.vibration import UNITS
                from inertialab.io.modelfile import dependency_versions
                from inertialab.report.figures.vibration import figures

                write_figures(figures(res), out_dir)
                save_model(res.model, out_dir / "model.json", units=UNITS,
                           training_data_sha256=sweep.sha256, settings=res.settings)
                report = res.to_report()
                report["inputs"] = [{"path": str(r.path), "sha256": r.sha256}
                                    for r in (sweep, fixed) if r is not None]
                report["dependencies"] = dependency_versions()
                atomic_write_text(out_dir / "result.json",
                                  json.dumps(to_jsonable(report), indent=1) + "\n")
        inputs = [sweep_file] + ([fixed_file] if fixed_file is not None else [])
        if as_json:
            emit_json("vibration", res.to_json(), inputs=inputs, settings=res.settings,
                      units=_JSON_UNITS, warnings_=warns)
            return
        rows = []
        for tname, table in res.tables.items():
            for rname, row in table.items():
                rows.append([tname, rname] + [row[k]["value"] for k in "QNBKR"])
        print_table(["table", "row", "Q [arcsec]", "N [deg/sqrt(h)]", "B [deg/h]",
                     "K [deg/h/sqrt(h)]", "R [deg/h^2]"], rows,
                    title=f"FOG vibration analysis, level L = {res.level}")
        f = res.fit
        print(f"RBF: {f['rbf']['neurons']} neurons, train RMSE {f['rbf']['train_rmse']:.4g}, "
              f"held-out RMSE {f['rbf']['heldout_rmse']:.4g} deg/h; polynomial: train RMSE "
              f"{f['poly']['train_rmse']:.4g}, held-out {f['poly']['heldout_rmse']:.4g} deg/h")
        if res.residual_bias_dph is not None:
            rb = res.residual_bias_dph
            print(f"residual bias: RBF {rb['rbf']:.4g} deg/h, polynomial {rb['poly']:.4g} deg/h")
        else:
            print(res.metrics["compensation_note"])
        if out is not None:
            print(f"wrote figures, model.json and result.json to {out}")

    @reading_options
    def vibration_apply(
        model_file: Path = typer.Argument(..., help="model.json written by 'inertialab "
                                                    "vibration fit --out'."),
        record_file: Path = typer.Argument(..., help="Record to compensate (gyro_log with "
                                                     "vib_on, vib_freq_hz)."),
        out: Path = typer.Option(..., "--out", help="Output record (CSV or Parquet) with "
                                                    "rate_comp_dph; a sidecar is written "
                                                    "beside it."),
        model: str = typer.Option("rbf", "--model", help="rbf | poly"),
        apply_to: str = typer.Option("denoised", "--apply-to", help="denoised (A_L, seed) | "
                                                                    "raw"),
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
        read: ReadOptions = None,
    ):
        """Apply a saved vibration-compensation model to a new record (spec §3.10)."""
        from inertialab.io import read_record, write_record
        from inertialab.workflows.registries import load_model
        from inertialab.workflows.vibration import apply

        if Path(out).is_dir():
            raise InputError("--out must be a file for this command", path=out)
        with collect_warnings(quiet=quiet) as warns:
            m = load_model(model_file, expected_type="vibration-compensation")
            rec = read_record(record_file, "gyro_log", options=read)
            res = apply(m, rec, model_name=model, apply_to=apply_to, model_path=str(model_file))
            write_record(res.data, out, res.meta)  # atomic: data file, then sidecar
        if as_json:
            emit_json("vibration apply", {"output": str(out), "residual": res.residual},
                      inputs=[model_file, record_file],
                      settings={"model": model, "apply_to": apply_to},
                      units={"residual": "deg/h"}, warnings_=warns)
            return
        print(f"wrote {out}: residual bias {res.residual['delta_b']:.4g} deg/h")

    vib.command("apply")(vibration_apply)
    # old spelling, hidden for one release
    app.command("vibration-compensate", hidden=True)(vibration_apply)

    @simulate.command("fog-vibration")
    def simulate_fog_vibration(
        experiment: str = typer.Option("fixed", "--experiment",
                                       help="sweep (E1, 1-500 Hz log sweep) | fixed (E2, "
                                            "500 Hz)."),
        seed: int = typer.Option(0, "--seed", help="Random seed."),
        preset: str = typer.Option("mid", "--preset", help="FOG grade: mid | nav | tactical."),
        out: Path = typer.Option(..., "--out", help="Record file (.csv or .parquet); the "
                                                    "sidecar is written beside it."),
        truth: Path = typer.Option(None, "--truth", help="Also write the truth table "
                                                         "(CSV) here."),
        p1_s: float = typer.Option(None, "--p1-s", help="P1 duration, s (default 1800)."),
        p3_s: float = typer.Option(None, "--p3-s", help="P3 duration, s (default 1800)."),
        p2_s: float = typer.Option(None, "--p2-s", help="Fixed-run P2 duration, s "
                                                        "(default 1800)."),
        acc_g: float = typer.Option(None, "--acc-g", help="Acceleration amplitude, g peak "
                                                          "(default 5)."),
        sweep_rate: float = typer.Option(None, "--sweep-oct-per-min",
                                         help="Sweep rate, octaves per minute (default 1)."),
        as_json: bool = typer.Option(False, "--json", help="Print a summary as JSON."),
    ):
        """Simulate a FOG on a linear shaker (spec 001 §6): three phases, §2.2 record."""
        from inertialab.io import write_record
        from inertialab.sim.fog_vibration import simulate as sim

        kw = {k: v for k, v in (("p1_s", p1_s), ("p3_s", p3_s), ("p2_fixed_s", p2_s),
                                ("acc_g", acc_g), ("sweep_oct_per_min", sweep_rate))
              if v is not None}
        if experiment not in ("sweep", "fixed"):
            raise InputError(f"--experiment must be sweep or fixed, got '{experiment}'")
        r = sim(experiment, seed, preset, **kw)
        if Path(out).is_dir():
            raise InputError("--out must be a file for this command", path=out)
        write_record(r.record, out, r.meta)
        if truth is not None:
            from inertialab.cli.common import atomic_write_text as _awt

            _awt(truth, r.truth.to_csv(index=False, lineterminator="\n"))
        if as_json:
            emit_json("simulate fog-vibration",
                      {"output": str(out), "n_samples": len(r.record),
                       "t_on_s": r.meta["t_on_s"], "t_off_s": r.meta["t_off_s"]},
                      inputs=[], settings={"experiment": experiment, "seed": seed,
                                           "preset": preset, **kw},
                      units={"t_on_s": "s", "t_off_s": "s"})
            return
        print(f"wrote {out} ({len(r.record)} samples, P2 {r.meta['t_on_s']:g}-"
              f"{r.meta['t_off_s']:g} s)")
