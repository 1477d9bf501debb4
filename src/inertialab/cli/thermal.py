"""``inertialab thermal fit / apply / export`` and ``inertialab simulate thermal-tumble``
(spec 000). Thin: parse, call :mod:`inertialab.workflows.thermal`, print or write.
``thermal compensate`` is the old spelling of ``thermal apply`` (hidden, one release).
``thermal fit`` runs through the runner (:mod:`inertialab.cli.runner`) with the settings of
:class:`inertialab.workflows.thermal_run.FitConfig`."""

from pathlib import Path
from typing import Annotated

import typer

from inertialab.cli.common import (
    collect_warnings,
    emit_json,
    prepare_out_dir,
    write_figures,
)
from inertialab.cli.options import JsonOpt, QuietOpt, reading_options
from inertialab.cli.runner import config_command
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.workflows import thermal_run as wt


def _plain(text: str) -> str:
    """Data-derived text for a matplotlib title: no mathtext (``$``), one line."""
    return " ".join(str(text).replace("$", r"\$").split())[:200]


def _read(path: Path, read: ReadOptions):
    from inertialab.io import read_record

    return read_record(path, "thermal_tumble", options=read)


def _apply_command(name: str):
    """The body of ``thermal apply`` (and of its old spelling ``thermal compensate``)."""

    @reading_options
    def thermal_apply(
        model: Annotated[Path, typer.Argument(help="model.json from 'thermal fit'.")],
        file: Annotated[Path, typer.Argument(help="thermal_tumble record to compensate.")],
        out: Annotated[Path, typer.Option("--out", help="Output record (.csv or .parquet); "
                                                        "a sidecar .meta.json is written "
                                                        "beside it.")],
        reference: Annotated[str, typer.Option(
            "--reference", help="model | record | auto: Ua with the model unit's 55 °C "
                                "coefficients, or with the record's own 55 °C tumble "
                                "(transfer to another unit, spec 000 §3.7); auto = record "
                                "when it has a full 55 °C tumble of another unit.")] = "auto",
        figure: Annotated[Path | None, typer.Option(
            "--figure", help="Also write the drift before/after compensation per input "
                             "level (seed Fig. 9, the transfer figure) to this .png; needs "
                             "a full tumble with a 55 °C set point.")] = None,
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
        read: ReadOptions | None = None,
    ):
        """Compensate a record with a thermal model; writes comp_output_mv, comp_a_g, status."""
        from inertialab.io import write_record
        from inertialab.workflows.registries import load_model
        from inertialab.workflows.thermal import apply

        with collect_warnings(quiet=quiet or as_json) as warns:
            mdl = load_model(model, expected_type="thermal-compensation")
            rec = _read(file, read)
            res = apply(mdl, rec, reference=reference, source=str(model))
        if Path(out).is_dir():
            raise InputError("--out must be a file for this command", path=out)
        fig = None
        if figure is not None:
            if Path(figure).suffix.lower() != ".png" or Path(figure).is_dir():
                raise InputError("--figure must name a .png file", path=figure)
            if res.drift is None:
                raise InputError("--figure needs a record with a full tumble at every set "
                                 "point and one at the reference temperature", path=file)
            from inertialab.report.figures.thermal import drift_figure

            who = "transfer" if res.reference == "record" else "own unit"
            fig = drift_figure(res.samples, res.drift, name=Path(figure).stem,
                               title=_plain(f"unit {res.samples.unit_id or '?'} with the model of unit "
                                     f"{mdl.unit_id or '?'} ({mdl.method}, {who})"))
        # everything is computed before this point: a failure leaves no output behind
        write_record(res.frame, out, res.meta)
        if fig is not None:
            write_figures([fig], Path(figure).parent)
        payload = res.summary() | {"out": str(out)}
        if as_json:
            emit_json(name, payload, inputs=[str(model), {"path": str(file), "sha256": rec.sha256}],
                      settings={"reference": reference.strip().lower()}, units={},
                      warnings_=warns)
            return
        print(f"compensated {payload['n_rows']} rows ({payload['n_clamped']} clamped) -> {out}")
        if res.drift is not None:
            print(f"drift vs 55 °C: raw max {res.drift.raw_max_ug / 1e3:.3f} mg, compensated max "
                  f"{res.drift.comp_max_ug:.2f} µg")

    return thermal_apply


@config_command(wt.FitConfig)
def thermal_fit(
    file: Annotated[Path, typer.Argument(help="thermal_tumble record (CSV or Parquet).")],
    *, config, run, read: ReadOptions | None = None,
):
    """Fit integrated temperature-compensation models on a thermal tumble record.

    --out writes model.json (IAFSA-SCM-ANFIS when fitted, else the first method),
    models/ (every method), result.json and figures of the saved model."""
    config.thermal_config()  # refuse bad settings before reading the record

    def figures(res):
        from inertialab.report.figures.thermal import (
            bias_figure,
            drift_figure,
            residual_figure,
            scale_factor_figure,
        )

        return [drift_figure(res.samples, res.own, title=res.result.model_method),
                residual_figure(res.result), bias_figure(res.bsf), scale_factor_figure(res.bsf)]

    run.execute("thermal fit", lambda bar: wt.run_fit(_read(file, read), config, progress=bar),
                inputs=lambda res: [{"path": str(file), "sha256": res.sha256}], figures=figures)


def register(app: typer.Typer, groups: dict) -> None:
    thermal, simulate = groups["thermal"], groups["simulate"]

    thermal.command("fit")(reading_options(thermal_fit))
    thermal.command("apply")(_apply_command("thermal apply"))
    thermal.command("compensate", hidden=True)(_apply_command("thermal compensate"))

    @thermal.command("export")
    @reading_options
    def thermal_export(
        model: Annotated[Path, typer.Argument(help="model.json of a fuzzy thermal model.")],
        c: Annotated[Path, typer.Option("--c", help="Directory for the C99 .h/.c pair.")],
        prefix: Annotated[str, typer.Option("--prefix", help="C identifier prefix.")] = "qfa",
        unit_record: Annotated[Path | None, typer.Option(
            "--unit-record", help="thermal_tumble record of the unit the code will run on, "
                                  "when it is another unit of the lot: its 55 °C tumble "
                                  "gives the transfer mapping of spec 000 §3.7.")] = None,
        as_json: JsonOpt = False,
        read: ReadOptions | None = None,
    ):
        """Export a fuzzy thermal model as dependency-free C99 (inputs clamped, status flag)."""
        from inertialab.io.exporters import get
        from inertialab.workflows.registries import load_model
        from inertialab.workflows.thermal import export

        mdl = load_model(model, expected_type="thermal-compensation")
        rec = _read(unit_record, read) if unit_record is not None else None
        ex = export(mdl, prefix=prefix, unit_record=rec)
        files = get("thermal", "c99").write(ex, prepare_out_dir(c))
        payload = {"files": files,
                   "n_rules": ex.n_rules, "exp_calls": ex.exp_calls, "flops": ex.flops,
                   "functions": [f"{prefix}_comp_mV", f"{prefix}_comp_g"],
                   "mapped_unit": None if rec is None else ex.unit_id}
        if as_json:
            inputs = [str(model)] + ([] if rec is None else
                                     [{"path": str(unit_record), "sha256": rec.sha256}])
            emit_json("thermal export", payload, inputs=inputs,
                      settings={"prefix": prefix, "unit_record": unit_record}, units={},
                      warnings_=[])
            return
        print(f"written: {payload['files'][0]}, {payload['files'][1]} "
              f"({ex.n_rules} rules, {ex.exp_calls} exp calls per reading)")

    @simulate.command("thermal-tumble")
    def simulate_thermal(
        out: Annotated[Path, typer.Option("--out", help="Record file (.csv or .parquet).")],
        preset: Annotated[str, typer.Option("--preset", help="paper | realistic")] = "paper",
        lot_seed: Annotated[int, typer.Option(
            "--lot-seed", help="Seed of the lot and its units.")] = 0,
        unit: Annotated[int, typer.Option("--unit", help="Unit index within the lot.")] = 0,
        seed: Annotated[int | None, typer.Option(
            "--seed", help="Run-noise seed (default: the lot seed).")] = None,
        ramp: Annotated[str, typer.Option("--ramp", help="up | up_down")] = "up",
        as_json: JsonOpt = False,
    ):
        """Write a virtual thermal tumble record (23 set points x 24 positions, spec 000 §7)."""
        from inertialab.io import write_record
        from inertialab.sim.thermal_tumble import simulate as sim

        if unit < 0:
            raise InputError(f"--unit must be >= 0, got {unit}")
        run = sim(preset, lot_seed, unit, seed=seed, ramp=ramp)
        out_path = Path(out)
        if out_path.exists() and out_path.is_dir():
            raise InputError("--out must be a file for this command", path=out_path)
        write_record(run.frame, out_path, run.meta)
        payload = {"out": str(out_path), "n_rows": int(len(run.frame)), "unit_id": run.unit.unit_id,
                   "noise_floor_ug": run.noise_floor_ug, "noise_only_ug": run.noise_only_ug}
        if as_json:
            emit_json("simulate thermal-tumble", payload, settings={
                "preset": preset, "lot_seed": lot_seed, "unit": unit,
                "seed": run.meta["seed"], "ramp": ramp}, units={}, warnings_=[])
            return
        print(f"written: {out_path} ({len(run.frame)} rows, unit {run.unit.unit_id}, "
              f"noise floor {run.noise_floor_ug:.2f} µg)")


__all__ = ["register"]
