"""``inertialab calibrate dual``, ``inertialab design dual``, ``inertialab simulate dual-tumble``
(spec 003). Thin: parse, call :mod:`inertialab.workflows.dual_tumble`, print or write."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from inertialab.cli.common import (
    atomic_write_text,
    collect_warnings,
    emit_json,
    prepare_out_dir,
    print_table,
    write_figures,
)
from inertialab.errors import InputError

_METHOD_CHOICES = ("ebr", "ls", "single-ls", "ridge-hkb", "ridge-gcv", "all")
_COEF_UNITS = {"KA0": "g", "KB0": "g", "kA1": "g/g", "kB1": "g/g", "eta": "rad",
               "KA2": "g/g^2", "KB2": "g/g^2", "KAx": "g/g^2", "KBx": "g/g^2",
               "delta_A": "rad", "delta_B": "rad", "residual": "g", "residual_raw": "g",
               "residual_val": "g"}


def register(app: typer.Typer, groups: dict) -> None:
    calibrate, design, simulate = groups["calibrate"], groups["design"], groups["simulate"]

    @calibrate.command("dual")
    def calibrate_dual(
        files: list[Path] = typer.Argument(..., help="dual_tumble record(s); two files with "
                                                     "opposite OA signs add the two-orientation fit."),
        method: str = typer.Option("all", "--method",
                                   help="ebr | ls | single-ls | ridge-hkb | ridge-gcv | all"),
        prior: str = typer.Option("none", "--prior",
                                  help="none (paper: beta0 = 0, W = I) | certificate | FILE "
                                       "(inertialab.prior/1 JSON, or a CSV of past calibrations)"),
        ebr_rule: str = typer.Option("E1", "--ebr-rule", help="E1 (Stein) | E2 (ML) | E3 (SURE)"),
        lambda_combination: str = typer.Option("star", "--lambda-combination",
                                               help="star | max | min of lambda* and lambda0"),
        second_order: bool = typer.Option(False, "--second-order",
                                          help="Iterated second-order correction of y (spec §1.5)."),
        g_local: float = typer.Option(None, "--g-local", help="Local gravity, m/s^2."),
        out: Path = typer.Option(None, "--out", help="Directory for model.json, result.json "
                                                     "and figures."),
        as_json: bool = typer.Option(False, "--json", help="Print the result as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="No progress or warnings on stderr."),
    ):
        """Calibrate two accelerometers tumbled on a dividing head (g^2 model, LS, EBR)."""
        from inertialab.io import read_record, save_model
        from inertialab.workflows.dual_tumble import (
            METHODS,
            calibrate,
            fit_two_orientation,
            head_error_sensitivity,
            reduce_record,
        )

        m = method.strip().lower()
        if m not in _METHOD_CHOICES:
            raise InputError(f"--method must be one of {', '.join(_METHOD_CHOICES)}, got '{method}'")
        methods = METHODS if m == "all" else (m,)
        if len(files) > 2:
            raise InputError("give one record, or two for the two-orientation fit")
        if out is not None and out.exists() and not out.is_dir():
            raise InputError("--out must be a directory for this command", path=out)
        with collect_warnings(quiet=quiet or as_json) as warns:
            records = [read_record(f, "dual_tumble", g_local=g_local) for f in files]
            reds = [reduce_record(r, g_local=g_local) for r in records]
            fit = calibrate(reds[0], methods=methods, prior=prior, second_order=second_order,
                            ebr_method=ebr_rule.upper(),
                            lambda_combination=lambda_combination.lower())
            two = fit_two_orientation(reds[0], reds[1]) if len(reds) == 2 else None
        payload = {"methods": {k: v.to_json() for k, v in fit.methods.items()},
                   "diagnostics": fit.diagnostics,
                   "model_method": fit.model.method}
        if two is not None:
            payload["two_orientation"] = two.to_json()
        truth = records[0].meta.get("truth")
        if isinstance(truth, dict):  # virtual-lab record: report errors vs truth (spec §4)
            from inertialab.workflows.dual_tumble import errors_vs_truth

            payload["errors_vs_truth"] = errors_vs_truth(fit, truth)
        all_warn = list(warns) + [w for w in fit.warnings if w not in warns]
        settings = {"method": m, "prior": prior, "ebr_rule": ebr_rule.upper(),
                    "lambda_combination": lambda_combination.lower(),
                    "second_order": second_order, "g_local": g_local, "seed": None}
        out_dir = prepare_out_dir(out) if out is not None else None  # only after success
        if out_dir is not None:
            from inertialab.report.figures.dual import (
                coefficient_figure,
                residual_figure,
                sensitivity_figure,
            )

            save_model(fit.model, out_dir / "model.json", units=_COEF_UNITS,
                       training_data_sha256=records[0].sha256)
            atomic_write_text(out_dir / "result.json",
                              json.dumps(_jsonable(payload), indent=2, allow_nan=False) + "\n")
            sm = tuple(x for x in ("single-ls", "ls", "ebr") if x in fit.methods) or ("ls",)
            sens = head_error_sensitivity(reds[0], methods=sm, prior=prior)
            write_figures([residual_figure(fit), coefficient_figure(fit),
                           sensitivity_figure(sens)], out_dir)
        if as_json:
            emit_json("calibrate dual", payload, inputs=files, settings=settings,
                      units=_COEF_UNITS, warnings_=all_warn)
            return
        if not quiet:
            import sys

            for w in fit.warnings:
                if not any(w in x for x in warns):
                    sys.stderr.write(f"warning: {' '.join(w.split())}\n")
        scale = {"KA0": (1e6, "ug"), "KB0": (1e6, "ug"), "kA1": (1e6, "ppm"),
                 "kB1": (1e6, "ppm"), "eta": (1e6, "urad"), "KA2": (1e6, "ug/g^2"),
                 "KB2": (1e6, "ug/g^2"), "KAx": (1e6, "ug/g^2"), "KBx": (1e6, "ug/g^2")}
        cols = list(fit.methods)
        rows = []
        for n, (f, u) in scale.items():
            row = [f"{n} ({u})"]
            for k in cols:
                r = fit.methods[k]
                v, sd = r.coef.get(n), r.sd.get(n)
                if v is None:
                    row.append("-")
                else:
                    sds = "n/e" if sd is None or sd != sd or sd == float("inf") else f"{sd * f:.3g}"
                    row.append(f"{v * f:+.4g} +- {sds}")
            rows.append(row)
        rows.append(["R (ug)"] + [f"{fit.methods[k].residual * 1e6:.3g}" for k in cols])
        rows.append(["R_val (ug)"] + [f"{fit.methods[k].r_val * 1e6:.3g}" for k in cols])
        rows.append(["rank"] + [str(fit.methods[k].rank) for k in cols])
        print_table(["coefficient", *cols], rows,
                    title="calibrate dual (n/e: not estimable; EBR SD = posterior)")
        if "ls" in fit.methods:
            for c in fit.methods["ls"].estimable:
                print(f"  estimable {c['name']:>9s} = {c['value']:+.4e} +- {c['sd']:.2e}")
        if two is not None:
            print("two-orientation LS: " + ", ".join(
                f"{n} = {two.coef[n]:+.3e} +- {two.sd[n] or float('nan'):.1e}"
                for n in ("KA2", "KB2", "KAx", "KBx")))
        if out_dir is not None:
            print(f"written: {out_dir}")

    @design.command("dual")
    def design_dual_cmd(
        positions: int = typer.Option(20, "--positions", help="Number of positions."),
        range_deg: tuple[float, float] = typer.Option((0.0, 360.0), "--range-deg",
                                                      help="Allowed angle range LO HI (deg)."),
        step_deg: float = typer.Option(1.0, "--step-deg", help="Candidate grid step (deg)."),
        as_json: bool = typer.Option(False, "--json", help="Print the result as JSON."),
    ):
        """D-optimal dividing-head positions for the identifiable g^2 harmonic model."""
        from inertialab.workflows.dual_tumble import design_dual

        with collect_warnings(quiet=as_json) as warns:
            res = design_dual(positions, range_deg=range_deg, step_deg=step_deg)
        if as_json:
            emit_json("design dual", res, settings={"positions": positions,
                                                    "range_deg": list(range_deg),
                                                    "step_deg": step_deg},
                      units={"positions_deg": "deg"}, warnings_=warns)
            return
        print("positions (deg): " + " ".join(f"{a:g}" for a in res["positions_deg"]))
        c, e = res["criteria"], res["equally_spaced"]["criteria"]
        print_table(["design", "log det (D)", "trace inv (A)", "min eig (E)", "cond"],
                    [["D-optimal", c["log_det"], c["a_trace_inv"], c["e_min_eig"], c["cond"]],
                     ["equally spaced", e["log_det"], e["a_trace_inv"], e["e_min_eig"],
                      e["cond"]]])
        print(res["note"])

    @simulate.command("dual-tumble")
    def simulate_dual(
        out: Path = typer.Option(..., "--out", help="Record file (.csv or .parquet)."),
        scenario: str = typer.Option("S1", "--scenario", help="S0 ... S5 (spec 003 §6.4)."),
        seed: int = typer.Option(20240603, "--seed", help="Random seed."),
        h: float = typer.Option(None, "--h", help="Head-error scale (S2 sweep; default 1)."),
        positions: int = typer.Option(None, "--positions", help="Positions per pass (S4)."),
        draw_unit: bool = typer.Option(False, "--draw-unit",
                                       help="Draw the unit around table 6.1 and write its "
                                            "historical prior as <stem>.prior.json."),
        as_json: bool = typer.Option(False, "--json", help="Print a summary as JSON."),
    ):
        """Write a virtual dual-tumble record (S5 writes <stem>_orient2 too)."""
        from inertialab.io import write_record
        from inertialab.sim.dual_tumble import (
            prior_from_history,
            scenario_config,
            simulate_run,
            simulate_two_orientation,
        )

        kw = {}
        if h is not None:
            kw["h"] = h
        if positions is not None:
            kw["n_positions"] = positions
        cfg = scenario_config(scenario, draw_unit=draw_unit, **kw)
        if cfg.scenario == "S5":
            runs = list(simulate_two_orientation(cfg, seed))
        else:
            runs = [simulate_run(cfg, seed)]
        paths = [out] + [out.with_name(f"{out.stem}_orient{i + 1}{out.suffix}")
                         for i in range(1, len(runs))]
        written = []
        for run, p in zip(runs, paths):
            meta = dict(run.meta)
            meta["seed"] = seed
            meta["truth"] = run.truth
            if p.exists() and p.is_dir():
                raise InputError("--out must be a file for this command", path=p)
            write_record(run.to_frame(), p, meta)  # data and sidecar, each atomically
            written.append(str(p))
        if draw_unit and "history" in runs[0].head:
            pj = {"schema": "inertialab.prior/1", "kind": "history",
                  "coef": prior_from_history(runs[0].head["history"])}
            prior_path = out.with_name(out.stem + ".prior.json")
            atomic_write_text(prior_path, json.dumps(pj, indent=2) + "\n")
            written.append(str(prior_path))
        if as_json:
            emit_json("simulate dual-tumble", {"written": written, "truth": runs[0].truth},
                      settings={"scenario": cfg.scenario, "seed": seed, "h": cfg.h,
                                "n_positions": cfg.n_positions, "draw_unit": draw_unit},
                      units=_COEF_UNITS)
            return
        print("written: " + ", ".join(written))


def _jsonable(obj):
    from inertialab.cli.common import json_ready

    return json_ready(obj)
