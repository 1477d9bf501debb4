"""``inertialab dual fit``, ``inertialab dual design`` and ``inertialab simulate dual-tumble``
(spec 003); ``calibrate dual`` and ``design dual`` are hidden aliases of the first two.
Thin: parse, call :mod:`inertialab.workflows.dual`, print or write.

No ``from __future__ import annotations`` here: the shared options are ``Annotated``
aliases that typer must see as objects through :func:`~inertialab.cli.options.reading_options`.
"""

import json
import sys
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
from inertialab.cli.options import JsonOpt, OutDirOpt, QuietOpt, SeedOpt, reading_options
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.workflows.dual import PAPER_ALIASES

_SCALE = {"KA0": (1e6, "ug"), "KB0": (1e6, "ug"), "kA1": (1e6, "ppm"),
          "kB1": (1e6, "ppm"), "eta": (1e6, "urad"), "KA2": (1e6, "ug/g^2"),
          "KB2": (1e6, "ug/g^2"), "KAx": (1e6, "ug/g^2"), "KBx": (1e6, "ug/g^2")}


@reading_options
def dual_fit(
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
    out: OutDirOpt = None,
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
    *,
    read: ReadOptions,
):
    """Calibrate two accelerometers tumbled on a dividing head (g^2 model, LS, EBR)."""
    from inertialab.io import read_record, save_model
    from inertialab.workflows import dual as wf

    methods = wf.parse_methods(method)
    m = method.strip().lower()
    if len(files) > 2:
        raise InputError("give one record, or two for the two-orientation fit")
    if out is not None and out.exists() and not out.is_dir():
        raise InputError("--out must be a directory for this command", path=out)
    config = wf.DualConfig(methods=methods, prior=prior, second_order=second_order,
                           ebr_rule=ebr_rule, lambda_combination=lambda_combination,
                           sensitivity=out is not None)
    with collect_warnings(quiet=quiet or as_json) as warns:
        records = [read_record(f, "dual_tumble", g_local=g_local, options=read) for f in files]
        reds = [wf.prepare(r, g_local=g_local) for r in records]
        res = wf.fit(reds, config, truth=records[0].meta.get("truth"))
    fit = res.fit
    payload = res.payload()
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

        save_model(res.model, out_dir / "model.json", units=wf.UNITS,
                   training_data_sha256=records[0].sha256)
        atomic_write_text(out_dir / "result.json",
                          json.dumps(json_ready(payload), indent=2, allow_nan=False) + "\n")
        write_figures([residual_figure(fit), coefficient_figure(fit),
                       sensitivity_figure(res.sensitivity)], out_dir)
    if as_json:
        emit_json("dual fit", payload, inputs=files, settings=settings,
                  units=wf.UNITS, warnings_=all_warn)
        return
    if not quiet:
        for w in fit.warnings:
            if not any(w in x for x in warns):
                sys.stderr.write(f"warning: {' '.join(w.split())}\n")
    cols = list(fit.methods)
    rows = []
    for n, (f, u) in _SCALE.items():
        label = f"{n} = {PAPER_ALIASES[n]}" if n in PAPER_ALIASES else n
        row = [f"{label} ({u})"]
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
                title="dual fit (n/e: not estimable; EBR SD = posterior)")
    if "ls" in fit.methods:
        for c in fit.methods["ls"].estimable:
            print(f"  estimable {c['name']:>9s} = {c['value']:+.4e} +- {c['sd']:.2e}")
    two = res.two_orientation
    if two is not None:
        print("two-orientation LS: " + ", ".join(
            f"{n} = {two.coef[n]:+.3e} +- {two.sd[n] or float('nan'):.1e}"
            for n in ("KA2", "KB2", "KAx", "KBx")))
    if out_dir is not None:
        print(f"written: {out_dir}")


def dual_design(
    positions: int = typer.Option(20, "--positions", help="Number of positions (7 to 360)."),
    range_deg: tuple[float, float] = typer.Option((0.0, 360.0), "--range-deg",
                                                  help="Allowed angle range LO HI (deg)."),
    step_deg: float = typer.Option(1.0, "--step-deg", help="Candidate grid step (deg; at "
                                                           "most 3601 candidates)."),
    as_json: JsonOpt = False,
):
    """D-optimal dividing-head positions for the identifiable g^2 harmonic model."""
    from inertialab.workflows.dual import design

    with collect_warnings(quiet=as_json) as warns:
        res = design(positions, range_deg=range_deg, step_deg=step_deg)
    if as_json:
        emit_json("dual design", res, settings={"positions": positions,
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


def simulate_dual(
    out: Path = typer.Option(..., "--out", help="Record file (.csv or .parquet)."),
    scenario: str = typer.Option("S1", "--scenario", help="S0 ... S5 (spec 003 §6.4)."),
    seed: SeedOpt = 20240603,
    h: float = typer.Option(None, "--h", help="Head-error scale (S2 sweep; default 1)."),
    positions: int = typer.Option(None, "--positions", help="Positions per pass (S4)."),
    draw_unit: bool = typer.Option(False, "--draw-unit",
                                   help="Draw the unit around table 6.1 and write its "
                                        "historical prior as <stem>.prior.json."),
    as_json: JsonOpt = False,
):
    """Write a virtual dual-tumble record (S5 writes <stem>_orient2 too)."""
    from inertialab.io import write_record
    from inertialab.sim.dual import scenario_config, simulate_run, simulate_two_orientation
    from inertialab.workflows.dual import UNITS, prior_from_history

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
                  units=UNITS)
        return
    print("written: " + ", ".join(written))


def register(app: typer.Typer, groups: dict) -> None:
    dual = groups["dual"]
    dual.command("fit")(dual_fit)
    dual.command("design")(dual_design)
    # old spellings, hidden for one release
    groups["calibrate"].command("dual", hidden=True)(dual_fit)
    groups["design"].command("dual", hidden=True)(dual_design)
    groups["simulate"].command("dual-tumble")(simulate_dual)
