"""``inertialab thermal fit / apply / export`` and ``inertialab simulate thermal-tumble``
(spec 000). Thin: parse, call :mod:`inertialab.workflows.thermal`, print or write.
``thermal compensate`` is the old spelling of ``thermal apply`` (hidden, one release)."""


import json
from pathlib import Path
from typing import Annotated

import typer

from inertialab.cli.common import (
    atomic_write_text,
    collect_warnings,
    emit_json,
    json_ready,
    prepare_out_dir,
    print_table,
    progress_bar,
    write_figures,
)
from inertialab.cli.options import JsonOpt, OutDirOpt, QuietOpt, SeedOpt, reading_options
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.units import THERMAL_UNITS

_METHOD_CHOICES = ("iafsa-scm-anfis", "scm-anfis", "anfis", "fis", "ann", "poly-sep", "poly-2d",
                   "all")


def _methods(method: str) -> tuple[str, ...]:
    from inertialab.workflows.thermal import METHODS

    m = method.strip().lower()
    if m == "all":
        return METHODS
    parts = tuple(p.strip() for p in m.split(",") if p.strip())
    bad = [p for p in parts if p not in _METHOD_CHOICES or p == "all"]
    if not parts or bad:
        raise InputError(f"--method must be one of {', '.join(_METHOD_CHOICES)} "
                         f"(or a comma-separated list), got '{method}'")
    return parts


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


def register(app: typer.Typer, groups: dict) -> None:
    thermal, simulate = groups["thermal"], groups["simulate"]

    @thermal.command("fit")
    @reading_options
    def thermal_fit(
        file: Annotated[Path, typer.Argument(help="thermal_tumble record (CSV or Parquet).")],
        method: Annotated[str, typer.Option(
            "--method", help="iafsa-scm-anfis | scm-anfis | anfis | fis | ann | poly-sep | "
                             "poly-2d | all (or a comma list)")] = "iafsa-scm-anfis",
        split: Annotated[str, typer.Option(
            "--split", help="random | interp_T | leave_one_T_out | up_down")] = "random",
        target: Annotated[str, typer.Option("--target", help="linear55 | measured55")] = "linear55",
        input_: Annotated[str, typer.Option("--input", help="ua (eq. 5) | raw (N = U)")] = "ua",
        learn_drift: Annotated[bool, typer.Option("--learn-drift", help="Learn Nc - N.")] = False,
        radii: Annotated[str, typer.Option("--radii", help="scalar | per_dim (IAFSA)")] = "scalar",
        fish: Annotated[int, typer.Option("--fish", help="IAFSA fish (spec: 10).")] = 10,
        generations: Annotated[int, typer.Option(
            "--generations", help="IAFSA generations (30).")] = 30,
        epochs: Annotated[int, typer.Option("--epochs", help="Final ANFIS epochs (150).")] = 150,
        search_epochs: Annotated[int, typer.Option(
            "--search-epochs", help="ANFIS epochs inside the IAFSA objective (20).")] = 20,
        visual: Annotated[float, typer.Option(
            "--visual", help="IAFSA initial visual range, unit-cube units (0.30).")] = 0.30,
        step: Annotated[float, typer.Option(
            "--step", help="IAFSA initial step, unit-cube units (0.10).")] = 0.10,
        try_number: Annotated[int, typer.Option(
            "--try-number", help="IAFSA prey attempts (5).")] = 5,
        crowd: Annotated[float, typer.Option(
            "--crowd", help="IAFSA crowd factor (0.618).")] = 0.618,
        seed: SeedOpt = 0,
        out: OutDirOpt = None,
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
        read: ReadOptions | None = None,
    ):
        """Fit integrated temperature-compensation models on a thermal tumble record.

        --out writes model.json (IAFSA-SCM-ANFIS when fitted, else the first method),
        models/ (every method), result.json and figures of the saved model."""
        from inertialab.io import save_model
        from inertialab.workflows.thermal import (
            ThermalConfig,
            bias_scale_factor,
            bias_scale_factor_table,
            fit,
            markdown_table,
            prepare,
        )

        methods = _methods(method)
        cfg = ThermalConfig(methods=methods, split=split, target=target, input=input_,
                            learn_drift=learn_drift, radii=radii, fish=fish,
                            generations=generations, epochs=epochs, search_epochs=search_epochs,
                            fish_visual=visual, fish_step=step, fish_try_number=try_number,
                            fish_crowd=crowd, seed=seed).validate()
        if "poly-sep" in methods and (learn_drift or input_ == "raw"):
            raise InputError("poly-sep needs --input ua without --learn-drift")
        if out is not None and Path(out).exists() and not Path(out).is_dir():
            raise InputError("--out must be a directory for this command", path=out)
        with collect_warnings(quiet=quiet or as_json) as warns:
            rec = _read(file, read)
            samples = prepare(rec, cfg)
            with progress_bar("thermal fit", quiet=quiet or as_json) as bar:
                result = fit(samples, cfg, progress=bar)
        main_model = result.models[result.model_method]
        own = result.own_drift()
        payload = result.summary(own)
        # everything is computed before the output folder is touched: bad input leaves
        # nothing behind
        out_dir = prepare_out_dir(out) if out is not None else None
        if out_dir is not None:
            from inertialab.report.figures.thermal import (
                bias_figure,
                drift_figure,
                residual_figure,
                scale_factor_figure,
            )

            units = {"temp": "degC", "output": "mV"}
            save_model(main_model, out_dir / "model.json", units=units,
                       training_data_sha256=rec.sha256)
            (out_dir / "models").mkdir(exist_ok=True)
            for m, mod in result.models.items():
                save_model(mod, out_dir / "models" / f"{m}.json", units=units,
                           training_data_sha256=rec.sha256)
            atomic_write_text(out_dir / "result.json",
                              json.dumps(json_ready(payload), indent=2, allow_nan=False) + "\n")
            for name, table, title in (
                    ("table1", result.table1(), "Table 1: fish-swarm parameters"),
                    ("table2", result.table2(), f"Table 2: test errors per model "
                                                f"({split} split, {result.test_index.size} "
                                                "test samples)")):
                atomic_write_text(out_dir / f"{name}.csv", table.to_csv(index=False))
                atomic_write_text(out_dir / f"{name}.md", markdown_table(table, title=title))
            bsf = bias_scale_factor(samples)
            atomic_write_text(out_dir / "bias_scale_factor.csv",
                              bias_scale_factor_table(bsf).to_csv(index=False))
            write_figures([drift_figure(samples, own, title=result.model_method),
                           residual_figure(result), bias_figure(bsf),
                           scale_factor_figure(bsf)], out_dir)
        settings = {"method": list(methods), "split": split, "target": target, "input": input_,
                    "learn_drift": learn_drift, "radii": radii, "fish": fish,
                    "generations": generations, "epochs": epochs, "search_epochs": search_epochs,
                    "visual": visual, "step": step, "try_number": try_number, "crowd": crowd,
                    "seed": seed, "reference_temp_c": samples.reference_temp_c}
        if as_json:
            emit_json("thermal fit", payload, inputs=[{"path": str(file), "sha256": rec.sha256}],
                      settings=settings, units=dict(THERMAL_UNITS), warnings_=warns)
            return
        rows = [[m, v.rmse_ug, v.me_ug, v.ae_ug, v.maxe_ppm, v.mare_ppm, v.rules, v.wall_s]
                for m, v in result.metrics.items()]
        print_table(["model", "RMSE µg", "ME µg", "AE µg", "MAXE ppm", "MARE ppm", "rules",
                     "wall s"], rows,
                    title=f"thermal fit ({split} split, raw drift RMS {result.raw_rms_ug:.0f} µg)")
        if result.search:
            s = result.search
            p = s["params"]
            print(f"IAFSA: radius={p['radius']}, squash={p['squash']:.4g}, accept={p['accept']:.4g}, "
                  f"reject={p['reject']:.4g}, rules={s['n_rules']}, "
                  f"F*={s['fun'] * 1e3:.2f} µg (default {s['f_default'] * 1e3:.2f})")
            t1 = payload["fish"]
            print("fish swarm (Table 1): " + ", ".join(f"{k}={v:g}" for k, v in t1.items()))
        if out_dir is not None:
            print(f"written: {out_dir}")

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
        from inertialab.workflows.registries import load_model
        from inertialab.workflows.thermal import export

        mdl = load_model(model, expected_type="thermal-compensation")
        rec = _read(unit_record, read) if unit_record is not None else None
        ex = export(mdl, prefix=prefix, unit_record=rec)
        out_dir = prepare_out_dir(c)
        atomic_write_text(out_dir / ex.header_name, ex.header)
        atomic_write_text(out_dir / ex.source_name, ex.source)
        payload = {"files": [str(out_dir / ex.header_name), str(out_dir / ex.source_name)],
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
