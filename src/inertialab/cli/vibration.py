"""``inertialab vibration fit|apply`` and ``inertialab simulate fog-vibration`` (spec 001).

Thin: parse, call :mod:`inertialab.workflows.vibration` (``fit``, ``apply``) /
:mod:`inertialab.sim.fog_vibration`, print or write. A bare ``inertialab vibration SWEEP
[FIXED]`` is routed to ``vibration fit`` by :mod:`inertialab.cli.main`; the old
``vibration-compensate`` spelling stays as a hidden alias of ``vibration apply``.
"""

# typer reads these signatures (the Annotated shared options of cli.options);
# plain annotations keep that independent of how reading_options evaluates them
from pathlib import Path

import typer

from inertialab.cli.common import (
    collect_warnings,
    emit_json,
)
from inertialab.cli.options import JsonOpt, QuietOpt, SeedOpt, reading_options
from inertialab.cli.runner import config_command
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.workflows import vibration_run as wv


@reading_options
@config_command(wv.FitConfig)
def vibration_fit(
    sweep_file: Path = typer.Argument(..., help="Sweep record (E1), gyro_log with vib_on, "
                                                "vib_freq_hz."),
    fixed_file: Path = typer.Argument(None, help="Fixed-frequency record (E2) to "
                                                 "compensate (optional)."),
    *, config, run, read: ReadOptions = None,
):
    """FOG under vibration: phase-wise Allan terms, db4 separation, RBF bias compensation
    (fit the bias model on the sweep; compensate the fixed run when given)."""
    from inertialab.io import read_record

    config.vibration_config(views=False)  # refuse bad settings before reading

    def produce(bar):
        sweep = read_record(sweep_file, "gyro_log", options=read)
        fixed = (read_record(fixed_file, "gyro_log", options=read)
                 if fixed_file is not None else None)
        return wv.run_fit(sweep, fixed, config, views=run.out is not None, progress=bar)

    def figures(res):
        from inertialab.report.figures.vibration import figures as vibration_figures

        return vibration_figures(res.res)

    run.execute("vibration", produce, figures=figures,
                inputs=[sweep_file] + ([fixed_file] if fixed_file is not None else []))


def register(app: typer.Typer, groups: dict) -> None:
    simulate = groups["simulate"]
    vib = groups["vibration"]

    vib.command("fit")(vibration_fit)

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
        seed: SeedOpt = 0,
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
        as_json: JsonOpt = False,
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
