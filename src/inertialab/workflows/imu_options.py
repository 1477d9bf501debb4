"""The six-axis options of ``allan --imu`` checked before any work.

:func:`check_options` runs before the record is read: the drift horizons
(``predict_drift``: comma-separated seconds, each finite, positive, at most
:data:`MAX_HORIZON_S`, none empty or given twice, at most :data:`MAX_HORIZONS` of them),
the check log (``check_on``: ``half`` or a file that is not the analysed log itself and
not empty), the noise-term method and the ROS topic of an export. :func:`check_horizons`
runs once the record is read and its warm-up span cut, before any fit: a horizon (with
its bias window) longer than what is fitted extrapolates the fitted model past every tau it saw and
is refused; a check log too short for a horizon's window gives no observation for it,
said in one warning (:func:`unusable_horizons`). Each refusal is one
:class:`~inertialab.errors.InputError` line naming the argument.
"""

from __future__ import annotations

import math
import os
import warnings
from pathlib import Path

from inertialab.errors import DataQualityWarning, InputError

#: Most horizons one prediction takes (each costs a numerical integral per term and axis;
#: 10 000 horizons ran for minutes).
MAX_HORIZONS = 100
#: Longest horizon, s (about 11.6 days; a horizon is also bounded by the record itself).
MAX_HORIZON_S = 1e6
#: Noise-term methods of :func:`inertialab.noise.terms.fit.fit_noise_terms`.
METHODS = ("wls", "ols", "slope", "gmwm")


def parse_horizons(predict_drift) -> tuple[float, ...]:
    """The horizons (s) of ``predict_drift`` (module docstring), or ``()`` when unset."""
    if predict_drift is None:
        return ()
    text = str(predict_drift)
    items = [v.strip() for v in text.split(",")]
    if not text.strip() or any(not v for v in items):
        raise InputError(f"argument 'predict_drift' has an empty horizon in '{text[:60]}': "
                         "give comma-separated seconds such as 1,10,60")
    if len(items) > MAX_HORIZONS:
        raise InputError(f"argument 'predict_drift' gives {len(items)} horizons; at most "
                         f"{MAX_HORIZONS}")
    out = []
    for v in items:
        try:
            h = float(v)
        except ValueError:
            raise InputError(f"argument 'predict_drift' must be comma-separated seconds, got "
                             f"'{v[:40]}'") from None
        if not (math.isfinite(h) and 0 < h <= MAX_HORIZON_S):
            raise InputError(f"argument 'predict_drift' horizon {v[:40]} s must be in "
                             f"(0, {MAX_HORIZON_S:g}] s")
        if h in out:
            raise InputError(f"argument 'predict_drift' gives the horizon {h:g} s twice")
        out.append(h)
    return tuple(out)


def check_options(file, method=None, rostopic=None, *, predict_drift=None, check_on=None,
                  export=True, **_other) -> tuple[float, ...]:
    """Refuse bad six-axis options before ``file`` is read (module docstring); returns
    the horizons (s). ``rostopic`` is checked when given with ``export`` (a false
    ``rostopic``: no export, nothing to check); other drift settings are ignored."""
    horizons = parse_horizons(predict_drift)
    if check_on is not None:
        c = str(check_on)
        if not c.strip():
            raise InputError("argument 'check_on' is empty: give half or another log of the "
                             "sensor")
        if c.strip().lower() != "half" and _same_file(c, file):
            raise InputError(f"argument 'check_on' names the analysed log itself ({c[:80]}): "
                             "a check needs other data; give half to check on the second "
                             "half")
    if method is not None and method not in METHODS:
        raise InputError(f"argument 'method' must be one of {', '.join(METHODS)}, got "
                         f"'{str(method)[:40]}'")
    if export and rostopic is not None:
        from inertialab.export import check_topic

        check_topic(rostopic)
    return horizons


def _same_file(a, b) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return Path(a).resolve() == Path(b).resolve()


def check_horizons(horizons, bias_window_s: float, record_s: float, *, check_s=None,
                   check_name: str | None = None, fitted_note: str = "") -> None:
    """Refuse a horizon whose bias window and horizon together are longer than the
    analysed record (``record_s``, the part the model is fitted on; ``fitted_note`` says
    what it is, e.g. after a warm-up cut); warn once, naming them, about horizons the
    check data (``check_s`` seconds of ``check_name``) cannot observe."""
    long = [h for h in horizons if h + bias_window_s > record_s]
    if long:
        raise InputError(f"argument 'predict_drift' horizon {long[0]:g} s with the "
                         f"{bias_window_s:g}-s bias window is longer than the "
                         f"{record_s:.6g} s the model is fitted on{fitted_note}: the "
                         "prediction would extrapolate the model past every tau it saw")
    bad = unusable_horizons(horizons, bias_window_s, check_s)
    if bad:
        warnings.warn(f"the drift check on {check_name} ({check_s:.6g} s) has no window of "
                      f"bias window + horizon for {', '.join(f'{h:g}' for h in bad)} s: "
                      "nothing observed there", DataQualityWarning, stacklevel=2)


def unusable_horizons(horizons, bias_window_s: float, check_s) -> list[float]:
    """The horizons for which ``check_s`` seconds of check data hold no window."""
    if check_s is None:
        return []
    return [h for h in horizons if h + bias_window_s > check_s]


__all__ = ["MAX_HORIZONS", "MAX_HORIZON_S", "METHODS", "check_horizons", "check_options",
           "parse_horizons", "unusable_horizons"]
