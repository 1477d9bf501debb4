"""``inertialab dual fit``, ``inertialab dual design`` and ``inertialab simulate dual-tumble``
(spec 003); ``calibrate dual`` and ``design dual`` are hidden aliases of the first two.
Thin: parse, call :mod:`inertialab.workflows.dual`, print or write.

No ``from __future__ import annotations`` here: the shared options are ``Annotated``
aliases that typer must see as objects through :func:`~inertialab.cli.options.reading_options`.
"""

import json
from pathlib import Path

import typer

from inertialab.cli.common import (
    atomic_write_text,
    collect_warnings,
    emit_json,
    print_table,
)
from inertialab.cli.options import JsonOpt, SeedOpt, reading_options
from inertialab.cli.runner import config_command
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.workflows import dual_run as wd


@reading_options
@config_command(wd.FitConfig)
def dual_fit(
    files: list[Path] = typer.Argument(..., help="dual_tumble record(s); two files with "
                                                 "opposite OA signs add the two-orientation fit."),
    *, config, run, read: ReadOptions,
):
    """Calibrate two accelerometers tumbled on a dividing head (g^2 model, LS, EBR)."""
    from inertialab.io import read_record

    if len(files) > 2:
        raise InputError("give one record, or two for the two-orientation fit")
    config.dual_config(sensitivity=False)  # refuse bad settings before reading

    def produce(bar):
        records = [read_record(f, "dual_tumble", g_local=config.g_local, options=read)
                   for f in files]
        return wd.run_fit(records, config, sensitivity=run.out is not None)

    def figures(res):
        from inertialab.report.figures.dual import (
            coefficient_figure,
            residual_figure,
            sensitivity_figure,
        )

        fit = res.res.fit
        return [residual_figure(fit), coefficient_figure(fit),
                sensitivity_figure(res.res.sensitivity)]

    run.execute("dual fit", produce, inputs=files, figures=figures)


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
