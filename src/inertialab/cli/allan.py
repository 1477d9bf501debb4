"""``inertialab allan FILE`` and ``inertialab simulate gyro-static``.

One ``allan`` command with every option: one series
(:mod:`inertialab.workflows.allan`) or, with ``--imu``, six IMU axes
(:mod:`inertialab.workflows.imu_noise`, Kalibr/ROS export); ``allan-imu`` is its hidden
old spelling (``--imu`` on by default). Thin: parse the options, read the record, call
the workflow, print the table and the noise terms (or its JSON object), write
the figure, ``result.json`` and ``model.json`` with ``--out``.
"""

# no "from __future__ import annotations": typer must see the Annotated shared options
import json
from pathlib import Path

import typer

from inertialab.cli.common import (
    atomic_write_text,
    collect_warnings,
    emit_json,
    json_ready,
    prepare_out_dir,
    print_table,
    write_figures,
)
from inertialab.cli.options import JsonOpt, QuietOpt, reading_options
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.workflows.registries import export_targets, stat_help

_EXPORT_HELP = ("TARGET FILE (six-axis mode): write the noise densities and random walks "
                "(continuous time, SI) for " + " | ".join(export_targets("noise")) + ".")
_IMU_HELP = ("Analyse gyro x/y/z and accelerometer x/y/z together (one table, one figure, "
             "noise densities and random walks).")


def _allan_command(imu_default: bool):
    """The ``allan`` command (``imu_default=False``) and its hidden old spelling
    ``allan-imu`` (``True``): one function, every option."""

    @reading_options
    def allan(
        file: Path = typer.Argument(..., help="Log file: CSV/Parquet (gyro_log) or a .npy "
                                              "column (needs --rate and --unit)."),
        column: str = typer.Option(None, "--column", help="Column to analyse (default: the "
                                                          "first rate/dtheta/accel column)."),
        rate: float = typer.Option(None, "--rate", help="Sample rate in Hz (default: from a "
                                                        "uniform t_s or the sidecar)."),
        input_: str = typer.Option("rate", "--input", help="rate | angle (cumulative "
                                   "theta_* column) | phase (clock time error) | frequency "
                                   "(clock fractional frequency)."),
        unit: str = typer.Option(None, "--unit", help="Unit of the data: dph, dps, rps, "
                                 "mps2, g ... (IMU); s, ms, us, ns, ps (phase); 1, ppm, ppb, "
                                 "ppt, hz (frequency; hz needs --nominal). Overrides the "
                                 "column suffix."),
        nominal: float = typer.Option(None, "--nominal", help="Nominal frequency, Hz, of a "
                                      "frequency record in hz: y = (f - nominal)/nominal."),
        stat: str = typer.Option("oadev", "--stat", help=stat_help()),
        taus: str = typer.Option("octave", "--taus", help="octave | decade | many | all | a "
                                 "count | comma-separated seconds."),
        terms: bool = typer.Option(None, "--terms/--no-terms", help="Fit the IMU noise terms "
                                   "Q N B K R (default: on for IMU logs, off for clocks)."),
        bias: bool = typer.Option(None, "--bias-correction/--no-bias-correction",
                                  help="Stable32 bias corrections of TOTDEV, MTOT, TTOT, "
                                  "HTOT, Theo1 (default: on for clocks, off for IMU logs)."),
        confidence: float = typer.Option(0.683, "--confidence", help="Two-sided confidence "
                                                                     "of the intervals."),
        method: str = typer.Option("wls", "--method", help="Noise terms: wls | ols | slope | "
                                                           "gmwm."),
        g_local: float = typer.Option(None, "--g-local", help="Local gravity, m/s^2 (g-based "
                                                              "accelerometer units)."),
        gaps: str = typer.Option(None, "--gaps", help="error | split: refuse time-stamp "
                                 "dropouts and repeats, or split the log at them (default: "
                                 "jitter and dropouts analysed on the sensor's grid, lost "
                                 "samples as gaps, with a warning)."),
        imu: bool = typer.Option(imu_default, "--imu", help=_IMU_HELP),
        export: tuple[str, str] = typer.Option(None, "--export", help=_EXPORT_HELP),
        rostopic: str = typer.Option("/imu0", "--rostopic", help="IMU topic in the Kalibr, "
                                     "OpenVINS and VINS files (six-axis mode)."),
        as_json: JsonOpt = False,
        out: Path = typer.Option(None, "--out", help="Directory for the figure, result.json "
                                                     "and model.json (noise terms)."),
        quiet: QuietOpt = False,
        read: ReadOptions = None,
    ):
        """Allan family with confidence intervals and the Q N B K R noise terms; --imu:
        six IMU axes in one table and figure, with Kalibr/ROS export."""
        command = "allan-imu" if imu_default else "allan"
        if imu or export:
            from inertialab.cli.imu_noise import run_six_axes

            if not imu:
                raise InputError("--export needs --imu (six-axis noise parameters)")
            return run_six_axes(file=file, export=export, rostopic=rostopic, read=read,
                                unit=unit, rate=rate, gaps=gaps, g_local=g_local,
                                method=method, out=out, as_json=as_json, quiet=quiet,
                                command=command)
        return _single(file=file, column=column, rate=rate, input_=input_, unit=unit,
                       nominal=nominal, stat=stat, taus=taus, confidence=confidence,
                       method=method, terms=terms, bias=bias, g_local=g_local, gaps=gaps,
                       as_json=as_json, out=out, quiet=quiet, read=read)

    return allan


def _single(*, file, column, rate, input_, unit, nominal, stat, taus, confidence, method, terms,
            bias, g_local, gaps, as_json, out, quiet, read):
    """One series: the table of each statistic and the noise terms."""
    from inertialab.io import read_record
    from inertialab.workflows.allan import (
        analyze,
        parse_stats,
        parse_taus,
        prepare_log,
        read_clock,
    )

    stats = parse_stats(stat)
    tau_spec = parse_taus(taus)
    if input_ not in ("rate", "angle", "phase", "frequency"):
        raise InputError(f"--input must be rate, angle, phase or frequency, got '{input_}'")
    clock = input_ in ("phase", "frequency")
    if not clock and unit is not None:
        from inertialab.workflows.allan import CLOCK_RATIO, CLOCK_TIME

        u = unit.strip().lower()
        if u in CLOCK_RATIO or u == "hz" or u in CLOCK_TIME:
            kind = "phase" if u in CLOCK_TIME else "frequency"
            raise InputError(f"--unit {unit} is a clock unit: give --input {kind} (clock "
                             f"{'time error' if kind == 'phase' else 'fractional frequency'})")
    if not 0.0 < confidence < 1.0:
        raise InputError(f"--confidence must be in (0, 1), got {confidence}")
    npy_col = None
    if Path(file).suffix.lower() == ".npy" and unit is not None:
        base = "theta" if input_ == "angle" else None
        if column is None and base is not None:
            npy_col = f"{base}_{unit.strip().lower()}"
    with collect_warnings(quiet) as warns:
        if clock:
            log = read_clock(file, input=input_, column=column, unit=unit, rate_hz=rate,
                             nominal_hz=nominal, options=read)
            sha = log.sha256
        else:
            rec = read_record(file, "gyro_log", unit=unit, rate_hz=rate,
                              column=column or npy_col, g_local=g_local, gaps=gaps,
                              options=read)
            log = prepare_log(rec, column=column, rate_hz=rate, input=input_, g_local=g_local)
            sha = rec.sha256
        res = analyze(log, stats=stats, taus=tau_spec, confidence=confidence, method=method,
                      fit_terms=terms, bias_correction=bias)
        payload = res.to_json()
        if out is not None:
            from inertialab.io import save_model
            from inertialab.report.figures.allan import deviation_figure
            from inertialab.report.figures.noise_terms import allan_terms_figure

            d = prepare_out_dir(out)
            figs = [deviation_figure(res)]
            if res.terms is not None and res.oadev is not None:
                figs.append(allan_terms_figure(res.oadev, res.terms))
            write_figures(figs, d)
            atomic_write_text(d / "result.json", json.dumps(json_ready(payload), indent=2) + "\n")
            if res.terms is not None:
                save_model(res.terms, d / "model.json", units={"rate": log.unit},
                           training_data_sha256=sha)
    settings = {"column": log.column, "rate_hz": log.rate_hz, "input": log.input,
                "stat": list(stats), "taus": taus, "confidence": confidence,
                "method": method, "unit": log.unit, "n_samples": res.n_samples}
    if clock:
        settings.update({"input": input_, "nominal_hz": nominal,
                         "bias_correction": res.settings.get("bias_correction"),
                         "noise_terms": res.settings.get("fit_terms")})
    if as_json:
        dev_units = {r.statistic: res.dev_unit(r.statistic) for r in res.results}
        one = next(iter(dev_units.values())) if len(set(dev_units.values())) == 1 else \
            "per statistic: see each result's unit"
        units = {"tau0_s": "s", "taus_s": "s", "dev": one, "ci_low": one,
                 "ci_high": one, "n_terms": "1", "alpha": "1", "edf": "1"}
        emit_json("allan", payload, inputs=[file], settings=settings, units=units,
                  warnings_=warns)
        return
    for r in res.results:
        print_table(["tau_s", "m", "dev", "ci_low", "ci_high", "n_terms", "alpha", "edf"],
                    [[t, int(m), d, lo, hi, int(n), int(a), e] for t, m, d, lo, hi, n, a, e
                     in zip(r.taus_s, r.m, r.dev, r.ci_low, r.ci_high, r.n_terms,
                            r.alpha, r.edf)],
                    title=f"{r.statistic.upper()} of {log.column} "
                          f"({res.dev_unit(r.statistic)}), {r.confidence:.1%} intervals")
    if res.terms is not None:
        rows = []
        for k, t in res.terms.terms().items():
            rows.append([k, t.value, t.unit, t.ci[0], t.ci[1], t.method,
                         f"{t.tau_range_s[0]:.3g}-{t.tau_range_s[1]:.3g}",
                         ",".join(t.flags)])
        n = res.terms.N
        if n.density is not None:
            rows.append(["N density", n.density["value"], n.density["unit"], None, None,
                         n.method, "continuous-time", ""])
        if n.per_sample_std is not None:
            rows.append(["N per-sample std", n.per_sample_std["value"],
                         n.per_sample_std["unit"], None, None, n.method,
                         f"at {log.rate_hz:g} Hz", ""])
        print_table(["term", "value", "unit", "ci_low", "ci_high", "method", "tau range s",
                     "flags"], rows, title="Noise terms (fitted on OADEV)")
    if out is not None:
        print(f"wrote {Path(out) / 'allan.png'}, result.json, model.json")


def register(app: typer.Typer, groups: dict) -> None:
    app.command("allan")(_allan_command(False))
    # old spelling, hidden for one release
    app.command("allan-imu", hidden=True)(_allan_command(True))

    simulate = groups["simulate"]

    @simulate.command("gyro-static")
    def simulate_gyro_static(
        preset: str = typer.Option("allan-test", "--preset", help="allan-test | allan-rrw | "
                                                                  "allan-bi | mid | nav | "
                                                                  "tactical."),
        hours: float = typer.Option(1.0, "--hours", help="Record length in hours."),
        rate: float = typer.Option(10.0, "--rate", help="Output rate in Hz."),
        seed: int = typer.Option(0, "--seed", help="Random seed."),
        out: Path = typer.Option(..., "--out", help="Record file (.csv or .parquet); the "
                                                    "sidecar is written beside it."),
        as_json: bool = typer.Option(False, "--json", help="Print a summary as JSON."),
    ):
        """A FOG at rest (spec 001 §6.2 noise model) with known Q N B K R."""
        from inertialab.io import write_record
        from inertialab.sim.gyro_static import simulate as sim

        if Path(out).is_dir():
            raise InputError("--out must be a file for this command", path=out)
        r = sim(preset, hours=hours, rate_hz=rate, seed=seed)
        write_record(r.record, out, r.meta)
        if as_json:
            emit_json("simulate gyro-static",
                      {"output": str(out), "n_samples": len(r.record),
                       "truth_terms": r.meta["truth_terms"]},
                      inputs=[], settings={"preset": preset, "hours": hours, "rate_hz": rate,
                                           "seed": seed},
                      units={"n_samples": "1"})
            return
        print(f"wrote {out} ({len(r.record)} samples at {rate:g} Hz, preset {preset})")
