"""The figures each command writes with ``--out``, one function per command taking the
workflow's result (the ``figures`` of :meth:`inertialab.cli.runner.Run.execute`). The
drawing modules (:mod:`inertialab.report.figures`) are imported on first use, so the
command line starts without matplotlib. File names that come from data (unit ids) go
through :func:`inertialab.io.names.safe_slug`.
"""

from __future__ import annotations

__all__ = ["batch", "drift_evaluate", "drift_fit", "dual_fit", "thermal_fit", "thermal_transfer",
           "triaxial_ferraris", "triaxial_fit", "vibration_fit"]


def vibration_fit(res) -> list:
    """``vibration fit``: the figures of the analysis."""
    from inertialab.report.figures.vibration import figures

    return figures(res.res)


def thermal_fit(res) -> list:
    """``thermal fit``: the saved model's drift and residuals, bias and scale factor."""
    from inertialab.report.figures.thermal import (
        bias_figure,
        drift_figure,
        residual_figure,
        scale_factor_figure,
    )

    return [drift_figure(res.samples, res.own, title=res.result.model_method),
            residual_figure(res.result), bias_figure(res.bsf), scale_factor_figure(res.bsf)]


def thermal_imu_fit(res) -> list:
    """``thermal fit --imu``: one figure per sensor instance (offset against temperature)."""
    from inertialab.report.figures.thermal_imu import imu_figures

    return imu_figures(res)


def thermal_transfer(res, name: str):
    """``thermal apply --figure``: the drift before and after compensation per input level
    (Fu et al., spec 000, Fig. 9); needs ``res.res.drift`` (a full tumble with a reference set point)."""
    from inertialab.report.figures.thermal import drift_figure

    r, mdl = res.res, res.model
    who = "transfer" if r.reference == "record" else "own unit"
    title = (f"unit {r.samples.unit_id or '?'} with the model of unit {mdl.unit_id or '?'} "
             f"({mdl.method}, {who})")  # data-derived: no mathtext, one line
    return drift_figure(r.samples, r.drift, name=name,
                        title=" ".join(title.replace("$", r"\$").split())[:200])


def triaxial_fit(res) -> list:
    """``triaxial fit``: sphere, norm error, coverage, convergence (and the per-method
    errors); none for a production-line batch (its table is the output)."""
    from inertialab.report.figures.triaxial import (
        convergence_figure,
        coverage_figure,
        method_errors_figure,
        norm_error_figure,
        sphere_figure,
    )

    if not hasattr(res, "run"):
        return []
    fit, data, cor = res.run.fit, res.run.data, res.corrected()
    m, obj = fit.method, res.run.model.objective
    figs = [sphere_figure(data.a, cor, data.g, title=f"{res.name}: measured vs corrected "
                                                      f"({m}, {obj})"),
            norm_error_figure({f"{m}-{obj}": res.norm_error()}),
            coverage_figure(cor, title=f"{res.name}: pose coverage")]
    if fit.history is not None:
        figs.append(convergence_figure({m: [fit.history]}))
    if res.tables is not None:
        figs.append(method_errors_figure(res.tables["poses"],
                                         title=f"{res.name}: error per pose and method"))
    return figs


def triaxial_ferraris(res) -> list:
    """``triaxial ferraris``: the detected sections of the session."""
    from inertialab.report.figures.triaxial import sections_figure

    s = res.session
    return [sections_figure(s.t, s.acc, s.gyro, s.sections, detection=s.detection,
                            title=f"{res.name}: Ferraris sections")]


def dual_fit(res) -> list:
    """``dual fit``: residuals, coefficients and their sensitivity."""
    from inertialab.report.figures.dual import (
        coefficient_figure,
        residual_figure,
        sensitivity_figure,
    )

    fit = res.res.fit
    return [residual_figure(fit), coefficient_figure(fit),
            sensitivity_figure(res.res.sensitivity)]


def drift_fit(res) -> list:
    """``drift fit``: per unit and quantity the fit, forecast, ACF and error curve; one
    re-calibration schedule."""
    from inertialab.io.names import safe_slug
    from inertialab.report.figures.drift import (
        acf_figure,
        error_curve_figure,
        fit_figure,
        forecast_figure,
        schedule_figure,
    )

    taken, slugs, figs = {"schedule"}, {}, []
    for u, q, r in res.fit.iter():
        s = slugs.setdefault(u, safe_slug(u, taken=taken))
        d = r.figure_data()
        figs += [fit_figure(d, f"fit_{q}_{s}"), forecast_figure(d, f"forecast_{q}_{s}"),
                 acf_figure(d, f"acf_{q}_{s}")]
        curve = r.error_curve()
        if curve:
            figs.append(error_curve_figure(curve, unit_id=u, quantity=q, unit=r.unit,
                                           name=f"error_curve_{q}_{s}"))
    figs.append(schedule_figure([
        {"unit_id": u, "quantity": q, "recalibration_day": r.recalibration_day,
         "origin_day": r.origin_day, "horizon_end": r.forecast["day"][-1]}
        for u, q, r in res.fit.iter()]))
    return figs


def drift_evaluate(res) -> list:
    """``drift evaluate``: the per-step error curve of each unit and quantity."""
    from inertialab.io.names import safe_slug
    from inertialab.report.figures.drift import error_curve_figure
    from inertialab.workflows.drift import UNITS

    taken: set = set()
    figs = []
    for u, d in res.per_unit.items():
        s = safe_slug(u, taken=taken)
        figs += [error_curve_figure(r.step_mae, unit_id=u, quantity=q, unit=UNITS[q],
                                    n_origins=len(r.origins), name=f"error_curve_{q}_{s}")
                 for q, r in d.items()]
    return figs


def batch(res) -> list:
    """``batch``: the fleet's key figures and yield."""
    from inertialab.report.figures.batch import batch_figure

    return [batch_figure(res.res)]
