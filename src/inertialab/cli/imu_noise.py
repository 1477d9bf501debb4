"""The six-axis mode of ``inertialab allan --imu`` (old spelling ``allan-imu``): six IMU
axes in one call, with Kalibr/ROS export (registered by :mod:`inertialab.cli.allan`)."""

from __future__ import annotations

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


def run_six_axes(*, file, export=None, rostopic="/imu0", read=None, unit=None, rate=None,
                 gaps=None, g_local=None, method="wls", out=None, as_json=False,
                 quiet=False, command="allan", terms=True, predict_drift=None,
                 bias_window=10.0, check_on=None, plan=False):
    """The six-axis mode of ``allan --imu`` (old spelling ``allan-imu``): read, analyse,
    export, print or emit JSON. ``read`` is the command's
    :class:`~inertialab.io.mapping.ReadOptions`."""
    from inertialab.io import read_record
    from inertialab.io.mapping import ReadOptions
    from inertialab.workflows.imu_noise import analyse_record, export_yaml

    export, export_file = export if export else (None, None)
    if export is not None and export not in ("kalibr", "ros"):
        raise InputError(f"--export must be 'kalibr' or 'ros', got '{export}'")
    if gaps not in (None, "error", "split"):
        raise InputError(f"--gaps must be 'error' or 'split', got '{gaps}'")
    ro = read if read is not None else ReadOptions()
    if (check_on or plan) and not predict_drift and not plan:
        raise InputError("--check-on needs --predict-drift")
    if not terms and (predict_drift or plan):
        raise InputError("--predict-drift and --plan need the noise terms (drop --no-terms)")
    with collect_warnings(quiet=quiet or as_json) as warns:
        rec = read_record(file, "gyro_log", unit=unit, rate_hz=rate, g_local=g_local,
                          gaps=gaps, options=ro)
        drift = _drift_options(predict_drift, bias_window, check_on, plan, rec, rate=rate,
                               unit=unit, g_local=g_local, gaps=gaps, ro=ro)
        with progress_bar("allan-imu", quiet=quiet) as bar:
            res = analyse_record(rec, rate_hz=rate, method=method, g_local=g_local,
                                 progress=bar, terms=terms, drift=drift)
    if export is not None:
        atomic_write_text(export_file, export_yaml(res, export, rostopic=rostopic))
    payload = {"imu": res.to_dict(), "sha256_canonical": rec.sha256}
    if out is not None:
        import json

        from inertialab.cli.common import json_ready
        from inertialab.report.figures.imu_noise import drift_figure, imu_figure

        d = prepare_out_dir(out)
        write_figures([f for f in (imu_figure(res), drift_figure(res)) if f is not None], d)
        atomic_write_text(d / "result.json", json.dumps(json_ready(payload), indent=2,
                                                       allow_nan=False))
    settings = {**res.settings, "map": ro.column_map.to_text() or None,
                "parse": ro.parse.to_dict(), "gaps": gaps, "export": export,
                "export_file": str(export_file) if export_file else None}
    if as_json:
        emit_json(command, payload, inputs=[file], settings=settings,
                  units={"rate_hz": "Hz"}, warnings_=warns)
        return
    cols, rows = res.table()
    print_table(cols, rows,
                title=f"{file}: IMU noise, {res.n_samples} samples at {res.rate_hz:g} Hz "
                      f"({100 * _term_confidence(res):g} % intervals; '<=' an upper bound; "
                      "densities continuous-time, SI)")
    for title, dcols, drows in drift_tables(res):
        print_table(dcols, drows, title=title)


def _term_confidence(res) -> float:
    for a in res.axes:
        if a.terms is not None:
            return float(a.terms.confidence)
    return 0.95


def _drift_options(predict_drift, bias_window, check_on, plan, rec, *, rate, unit, g_local,
                   gaps, ro):
    """The :class:`~inertialab.workflows.imu_drift.DriftOptions` of the flags (the
    ``--check-on`` log read like the main one), or None."""
    if not predict_drift and not plan:
        return None
    from inertialab.workflows.imu_drift import DriftOptions

    horizons = ()
    if predict_drift:
        try:
            horizons = tuple(float(v) for v in str(predict_drift).split(",") if v.strip())
        except ValueError:
            raise InputError(f"--predict-drift must be comma-separated seconds, got "
                             f"'{predict_drift}'") from None
    other, name, mode = {}, None, None
    if check_on:
        if str(check_on).strip().lower() == "half":
            mode = "half"
        else:
            from inertialab.io import read_record
            from inertialab.workflows.imu_noise import axis_columns

            rec2 = read_record(check_on, "gyro_log", unit=unit, rate_hz=rate,
                               g_local=g_local, gaps=gaps, options=ro)
            tb1, tb2 = rec.timebase, rec2.timebase
            fs1 = rate or (tb1.rate_hz if tb1 is not None else None)
            fs2 = rate or (tb2.rate_hz if tb2 is not None else None)
            if fs1 and fs2 and abs(float(fs1) / float(fs2) - 1) > 1e-3:
                raise InputError(f"--check-on log is at {fs2:g} Hz, the analysed log at "
                                 f"{fs1:g} Hz: give logs of the same rate", path=check_on)
            place = tb2.place if (rate is None and tb2 is not None) else (lambda v: v)
            other = {k: place(v[1]) for k, v in axis_columns(rec2).items()}
            mode, name = "other", str(check_on)
    return DriftOptions(horizons_s=horizons or (1.0,), bias_window_s=float(bias_window),
                        check_on=mode, other=other, other_name=name, plan=bool(plan))


def drift_tables(res) -> list:
    """``(title, columns, rows)`` of the predicted-drift, check and plan tables."""
    out = []
    axes = [a for a in res.axes if a.drift is not None]
    if axes and res.settings.get("drift", {}).get("horizons_s"):
        hz = axes[0].drift["horizons_s"]
        w = axes[0].drift["bias_window_s"]
        cols = ["axis", "source"] + [f"{h:g} s" for h in hz]
        rows = []
        for a in axes:
            d, u = a.drift, a.drift["unit"]
            rows.append([a.axis, f"model RMS ({u})"] + [f"{v:.3g}" for v in d["predicted_rms"]])
            rows.append([a.axis, f"Kalibr RMS ({u})"]
                        + [f"{v:.3g}" for v in d["kalibr"]["predicted_rms"]])
            c = d.get("check")
            if c:
                rows.append([a.axis, f"observed RMS ({u})"]
                            + [f"{v:.3g}" for v in c["observed_rms"]])
                rows.append([a.axis, "observed/model"]
                            + [f"{v:.2f}" for v in c["observed_over_predicted"]])
                rows.append([a.axis, "observed/Kalibr"]
                            + [f"{v:.2f}" for v in c["kalibr_observed_over_predicted"]])
                rows.append([a.axis, "in model 95 % band"]
                            + [f"{100 * v:.0f} %" for v in c["coverage_95"]])
        check = axes[0].drift.get("check", {}).get("on")
        out.append((f"Integrated error after a {w:g}-s bias window (angle for gyros, "
                    "velocity for accelerometers)" + (f"; checked on {check}" if check
                                                      else ""), cols, rows))
    plans = [a for a in res.axes if a.plan is not None]
    if plans:
        rows = [[a.axis, "-" if a.plan["needed_h"] is None else f"{a.plan['needed_h']:.3g}",
                 f"{a.plan['record_h']:.3g}",
                 {True: "yes", False: "no", None: "-"}[a.plan["long_enough"]],
                 a.plan.get("reason", "")] for a in plans]
        out.append(("Record length for K within +-20 % at 95 % (Cramer-Rao bound of the "
                    "fitted model)", ["axis", "needed (h)", "this log (h)", "long enough",
                                      "note"], rows))
    return out
