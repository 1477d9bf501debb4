"""The pooled mode of ``allan --imu LOG1 LOG2 ... --pool``: several logs as one noise
model per axis (:mod:`inertialab.workflows.imu_pool`), registered by
:mod:`inertialab.cli.allan`."""

from __future__ import annotations

from inertialab.cli import common as C
from inertialab.errors import InputError


def run_pool(*, files, read=None, unit=None, rate=None, gaps=None, g_local=None, out=None,
             as_json=False, quiet=False, command="allan", drift=None, confidence=None,
             warmup="auto", pool_kind="runs"):
    """Read and pool the logs, print the tables or emit the JSON (``imu``: the pooled
    six-axis layout, each axis with ``logs[]``), write ``result.json`` and the figure
    with ``out``."""
    from inertialab.io.mapping import ReadOptions
    from inertialab.workflows.imu_pool import analyse_pool

    ro = read if read is not None else ReadOptions()
    d = dict(drift or {})
    for k in ("plan", "inflate"):
        if d.pop(k, None):
            raise InputError(f"argument '{k}' is not available with argument 'pool'")
    with C.collect_warnings(quiet=quiet or as_json) as warns:
        with C.progress_bar("allan-imu --pool", quiet=quiet) as bar:
            res = analyse_pool([str(f) for f in files], read=ro, unit=unit, rate=rate,
                               gaps=gaps, g_local=g_local, warmup=warmup,
                               pool_kind=pool_kind, predict_drift=d.get("predict_drift"),
                               bias_window=d.get("bias_window", 10.0),
                               check_on=d.get("check_on"),
                               confidence=0.95 if confidence is None else confidence,
                               progress=bar)
    payload = {"imu": res.to_dict()}
    if out is not None:
        import json

        from inertialab.report.figures.imu_noise import imu_figures

        od = C.prepare_out_dir(out)
        C.write_figures(imu_figures(res.imu), od)
        C.atomic_write_text(od / "result.json", json.dumps(C.json_ready(payload), indent=2,
                                                        allow_nan=False))
    if as_json:
        return C.emit_json(command, payload, inputs=[str(f) for f in files],
                           settings=res.imu.settings, units={"rate_hz": "Hz"},
                           warnings_=warns)
    for title, cols, rows in res.tables():
        C.print_table(cols, rows, title=title)
