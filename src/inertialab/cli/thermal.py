"""``inertialab thermal fit / compensate / export`` and ``inertialab simulate thermal-tumble``
(spec 000). Thin: parse, call :mod:`inertialab.workflows.thermal`, print or write."""

from __future__ import annotations

import json
from dataclasses import replace
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
from inertialab.errors import InputError

_METHOD_CHOICES = ("iafsa-scm-anfis", "scm-anfis", "anfis", "fis", "ann", "poly-sep", "poly-2d",
                   "all")
_MODEL_KEYS = ("rmse_ug", "me_ug", "ae_ug", "mbe_ug", "maxe_ppm", "mare_ppm", "rmse_truth_ug",
               "rules", "wall_s")
_UNITS = {"temp": "degC", "output": "mV", "k0": "mV", "k1": "mV/g", "k2": "mV/g^2",
          "kip": "mV/g^2", "kp": "mV/g", "wall_s": "s", "fun": "mg", "f_default": "mg",
          "radius": "1 (scaled)", "squash": "1", "accept": "1", "reject": "1"}


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


def _read(path: Path):
    from inertialab.io import read_record

    return read_record(path, "thermal_tumble")


def _reference_temp(meta: dict, path) -> float:
    """The sidecar's reference temperature (``reference_temp_C``, any case), else 55 °C."""
    for k, v in meta.items():
        if str(k).lower() == "reference_temp_c":
            try:
                return float(v)
            except (TypeError, ValueError):
                raise InputError(f"sidecar key {k} is not a number: {v!r}", path=path) from None
    return 55.0


def register(app: typer.Typer, groups: dict) -> None:
    thermal, simulate = groups["thermal"], groups["simulate"]

    @thermal.command("fit")
    def thermal_fit(
        file: Path = typer.Argument(..., help="thermal_tumble record (CSV or Parquet)."),
        method: str = typer.Option("iafsa-scm-anfis", "--method",
                                   help="iafsa-scm-anfis | scm-anfis | anfis | fis | ann | "
                                        "poly-sep | poly-2d | all (or a comma list)"),
        split: str = typer.Option("random", "--split", help="random | interp_T | leave_one_T_out | up_down"),
        target: str = typer.Option("linear55", "--target", help="linear55 | measured55"),
        input_: str = typer.Option("ua", "--input", help="ua (eq. 5) | raw (N = U)"),
        learn_drift: bool = typer.Option(False, "--learn-drift", help="Learn Nc - N."),
        radii: str = typer.Option("scalar", "--radii", help="scalar | per_dim (IAFSA)"),
        fish: int = typer.Option(10, "--fish", help="IAFSA fish (spec: 10)."),
        generations: int = typer.Option(30, "--generations", help="IAFSA generations (30)."),
        epochs: int = typer.Option(150, "--epochs", help="Final ANFIS epochs (150)."),
        search_epochs: int = typer.Option(20, "--search-epochs",
                                          help="ANFIS epochs inside the IAFSA objective (20)."),
        seed: int = typer.Option(0, "--seed", help="Seed of split, search and ANN."),
        out: Path = typer.Option(None, "--out", help="Directory for model.json (the first "
                                                     "method), models/, result.json, figures."),
        as_json: bool = typer.Option(False, "--json", help="Print the result as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="No progress or warnings on stderr."),
    ):
        """Fit integrated temperature-compensation models on a thermal tumble record."""
        from inertialab.io import save_model
        from inertialab.workflows.thermal import ThermalConfig, drift, fit_thermal, prepare_samples

        methods = _methods(method)
        cfg = ThermalConfig(methods=methods, split=split, target=target, input=input_,
                            learn_drift=learn_drift, radii=radii, fish=fish,
                            generations=generations, epochs=epochs, search_epochs=search_epochs,
                            seed=seed).validate()
        if "poly-sep" in methods and (learn_drift or input_ == "raw"):
            raise InputError("poly-sep needs --input ua without --learn-drift")
        out_dir = prepare_out_dir(out) if out is not None else None
        with collect_warnings(quiet=quiet or as_json) as warns:
            rec = _read(file)
            cfg = replace(cfg, reference_temp_c=_reference_temp(rec.meta, file))
            samples = prepare_samples(rec.data, cfg, path=file)
            with progress_bar("thermal fit", quiet=quiet or as_json) as bar:
                fit = fit_thermal(samples, cfg, progress=bar)
        main_model = fit.models[methods[0]]
        own = drift(main_model, samples, own_unit=True)
        payload = {
            "models": {m: {k: v.to_dict()[k] for k in _MODEL_KEYS} for m, v in fit.metrics.items()},
            "scm": {m: mod.scm for m, mod in fit.models.items() if mod.scm is not None},
            "search": None if fit.search is None else {
                k: fit.search[k] for k in ("params", "fun", "f_default", "n_rules", "nfev", "nit",
                                           "wall_s", "message")},
            "raw_rms_ug": fit.raw_rms_ug,
            "reference": samples.ref.to_dict(),
            "model_method": methods[0],
            "drift": own.summary(),
            "n_samples": samples.n, "n_test": int(fit.test_index.size),
        }
        if out_dir is not None:
            from inertialab.report.figures.thermal import drift_figure, residual_figure

            units = {"temp": "degC", "output": "mV"}
            save_model(main_model, out_dir / "model.json", units=units,
                       training_data_sha256=rec.sha256)
            (out_dir / "models").mkdir(exist_ok=True)
            for m, mod in fit.models.items():
                save_model(mod, out_dir / "models" / f"{m}.json", units=units,
                           training_data_sha256=rec.sha256)
            from inertialab.cli.common import json_ready

            atomic_write_text(out_dir / "result.json",
                              json.dumps(json_ready(payload), indent=2, allow_nan=False) + "\n")
            write_figures([drift_figure(samples, own, title=methods[0]), residual_figure(fit)],
                          out_dir)
        settings = {"method": list(methods), "split": split, "target": target, "input": input_,
                    "learn_drift": learn_drift, "radii": radii, "fish": fish,
                    "generations": generations, "epochs": epochs, "search_epochs": search_epochs,
                    "seed": seed, "reference_temp_c": cfg.reference_temp_c}
        if as_json:
            units = dict(_UNITS)
            emit_json("thermal fit", payload, inputs=[{"path": str(file), "sha256": rec.sha256}],
                      settings=settings, units=units, warnings_=warns)
            return
        rows = [[m, v.rmse_ug, v.me_ug, v.ae_ug, v.maxe_ppm, v.mare_ppm, v.rules, v.wall_s]
                for m, v in fit.metrics.items()]
        print_table(["model", "RMSE µg", "ME µg", "AE µg", "MAXE ppm", "MARE ppm", "rules",
                     "wall s"], rows,
                    title=f"thermal fit ({split} split, raw drift RMS {fit.raw_rms_ug:.0f} µg)")
        if fit.search:
            p = fit.search["params"]
            print(f"IAFSA: radius={p['radius']}, squash={p['squash']:.4g}, accept={p['accept']:.4g}, "
                  f"reject={p['reject']:.4g}, rules={fit.search['n_rules']}, "
                  f"F*={fit.search['fun'] * 1e3:.2f} µg (default {fit.search['f_default'] * 1e3:.2f})")
        if out_dir is not None:
            print(f"written: {out_dir}")

    @thermal.command("compensate")
    def thermal_compensate(
        model: Path = typer.Argument(..., help="model.json from 'thermal fit'."),
        file: Path = typer.Argument(..., help="thermal_tumble record to compensate."),
        out: Path = typer.Option(..., "--out", help="Output record (.csv or .parquet)."),
        reference: str = typer.Option("auto", "--reference",
                                      help="model | record | auto: Ua with the model unit's 55 °C "
                                           "coefficients, or with the record's own 55 °C tumble "
                                           "(transfer to another unit, spec 000 §3.7); auto = "
                                           "record when it has a full 55 °C tumble of another "
                                           "unit."),
        as_json: bool = typer.Option(False, "--json", help="Print a summary as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="No warnings on stderr."),
    ):
        """Compensate a record with a thermal model; writes comp_output_mv, comp_a_g, status."""
        import numpy as np

        from inertialab.io import load_model, write_record
        from inertialab.workflows.thermal import ThermalConfig, compensate, drift, prepare_samples

        ref_mode = reference.strip().lower()
        if ref_mode not in ("auto", "model", "record"):
            raise InputError(f"--reference must be auto, model or record, got '{reference}'")
        with collect_warnings(quiet=quiet or as_json) as warns:
            mdl = load_model(model, expected_type="thermal-compensation")
            rec = _read(file)
            d = rec.data
            samples = None
            if ref_mode in ("auto", "record"):
                try:
                    cfg = ThermalConfig(input=mdl.input, target=mdl.target,
                                        reference_temp_c=mdl.reference_temp_c)
                    samples = prepare_samples(d, cfg, path=file)
                except InputError:
                    if ref_mode == "record":
                        raise
            same_unit = "unit_id" in d and str(d["unit_id"].iloc[0]) == mdl.unit_id
            use_record = samples is not None and (ref_mode == "record" or not same_unit)
            unit_ref = samples.ref if use_record else None
            a_p = d["a_pend_g"].to_numpy() if "a_pend_g" in d else None
            comp = compensate(mdl, d["temp_meas_c"].to_numpy(), d["output_mv"].to_numpy(), a_p,
                              unit_ref=unit_ref, path=file)
            dr = None
            if samples is not None:
                dr = drift(mdl, samples, own_unit=not use_record)
        outf = d.copy()
        outf["comp_output_mv"] = comp.nc_mv
        outf["comp_a_g"] = comp.a_g
        outf["status"] = comp.status
        meta = dict(rec.meta)
        meta.update({"compensated_with": str(model), "model_method": mdl.method,
                     "reference": "record" if use_record else "model"})
        if Path(out).is_dir():
            raise InputError("--out must be a file for this command", path=out)
        # everything is computed before this point: a failure leaves no output behind
        write_record(outf, out, meta)
        counts = {str(k): int(v) for k, v in zip(*np.unique(comp.status, return_counts=True))}
        payload = {"n_rows": int(len(d)), "n_clamped": int(np.count_nonzero(comp.status)),
                   "status_counts": counts, "reference": "record" if use_record else "model",
                   "drift": None if dr is None else dr.summary(), "out": str(out)}
        if as_json:
            emit_json("thermal compensate", payload,
                      inputs=[str(model), {"path": str(file), "sha256": rec.sha256}],
                      settings={"reference": ref_mode}, units={}, warnings_=warns)
            return
        print(f"compensated {len(d)} rows ({payload['n_clamped']} clamped) -> {out}")
        if dr is not None:
            print(f"drift vs 55 °C: raw max {dr.raw_max_ug / 1e3:.3f} mg, compensated max "
                  f"{dr.comp_max_ug:.2f} µg")

    @thermal.command("export")
    def thermal_export(
        model: Path = typer.Argument(..., help="model.json of a fuzzy thermal model."),
        c: Path = typer.Option(..., "--c", help="Directory for the C99 .h/.c pair."),
        prefix: str = typer.Option("qfa", "--prefix", help="C identifier prefix."),
        as_json: bool = typer.Option(False, "--json", help="Print a summary as JSON."),
    ):
        """Export a fuzzy thermal model as dependency-free C99 (inputs clamped, status flag)."""
        from inertialab.io import load_model
        from inertialab.workflows.thermal_export import export_c

        mdl = load_model(model, expected_type="thermal-compensation")
        ex = export_c(mdl, prefix=prefix)
        out_dir = prepare_out_dir(c)
        atomic_write_text(out_dir / ex.header_name, ex.header)
        atomic_write_text(out_dir / ex.source_name, ex.source)
        payload = {"files": [str(out_dir / ex.header_name), str(out_dir / ex.source_name)],
                   "n_rules": ex.n_rules, "exp_calls": ex.exp_calls, "flops": ex.flops,
                   "functions": [f"{prefix}_comp_mV", f"{prefix}_comp_g"]}
        if as_json:
            emit_json("thermal export", payload, inputs=[str(model)], settings={"prefix": prefix},
                      units={}, warnings_=[])
            return
        print(f"written: {payload['files'][0]}, {payload['files'][1]} "
              f"({ex.n_rules} rules, {ex.exp_calls} exp calls per reading)")

    @simulate.command("thermal-tumble")
    def simulate_thermal(
        out: Path = typer.Option(..., "--out", help="Record file (.csv or .parquet)."),
        preset: str = typer.Option("paper", "--preset", help="paper | realistic"),
        lot_seed: int = typer.Option(0, "--lot-seed", help="Seed of the lot and its units."),
        unit: int = typer.Option(0, "--unit", help="Unit index within the lot."),
        seed: int = typer.Option(None, "--seed", help="Run-noise seed (default: the lot seed)."),
        ramp: str = typer.Option("up", "--ramp", help="up | up_down"),
        as_json: bool = typer.Option(False, "--json", help="Print a summary as JSON."),
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
        out_path.parent.mkdir(parents=True, exist_ok=True)
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
