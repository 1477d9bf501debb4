"""The result of a six-axis noise analysis (``allan --imu``,
:func:`inertialab.workflows.imu_noise.analyse_imu`): per axis its Allan deviation, noise
terms and the two numbers visual-inertial estimators ask for (:class:`AxisNoise`), and
the six axes together (:class:`IMUNoise`) with their display table and notes.

Units: ``noise_density`` is the continuous-time white-noise density ``N`` (rad/s/sqrt(Hz)
for gyros, m/s^2/sqrt(Hz) for accelerometers), ``random_walk`` the continuous-time bias
random walk ``K`` (rad/s^2/sqrt(Hz), m/s^3/sqrt(Hz)) and ``bias_instability`` ``B``
(rad/s, m/s^2), all SI (:data:`SI_UNITS`). The files other tools read are written by
:mod:`inertialab.export` from these results.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from inertialab.config import DEFAULT_CONFIDENCE

__all__ = ["SI_UNITS", "AxisNoise", "IMUNoise", "stationarity_text", "term_text"]

#: kind -> (SI unit suffix, noise-density unit, random-walk unit)
SI_UNITS = {"gyro": ("rps", "rad/s/sqrt(Hz)", "rad/s^2/sqrt(Hz)"),
       "accel": ("mps2", "m/s^2/sqrt(Hz)", "m/s^3/sqrt(Hz)")}


@dataclass(frozen=True)
class AxisNoise:
    """Noise of one axis.

    Attributes
    ----------
    axis : str            ``gx gy gz ax ay az``
    column : str          the record column analysed (with its unit suffix)
    kind : str            ``gyro`` or ``accel``
    unit : str            unit suffix of the data
    deviation : DeviationResult
    terms : NoiseTerms
    noise_density : float
        Continuous-time white-noise density, SI (rad/s/sqrt(Hz) or m/s^2/sqrt(Hz)).
    random_walk : float
        Continuous-time bias random walk, SI (rad/s^2/sqrt(Hz) or m/s^3/sqrt(Hz)).
    random_walk_bound : bool
        ``random_walk`` is an upper bound (K not significant, or no +1/2 slope).
    random_walk_t_s : float or None
        The Gauss–Markov correlation time (s) that holds the random walk (the fit's
        ``terms.k_gm``): ``random_walk`` is its density below it. None: a pure random walk.
    bias_instability : float
        B of the noise-term fit, SI (rad/s or m/s^2).
    bias_instability_bound : bool
        ``bias_instability`` is an upper bound (B not significant).
    status : str
        ``ok``, ``not static`` (terms not fitted: the curve follows motion, not the
        sensor; ``reason`` says why), ``constant`` or ``stuck`` (every sample, or a run of
        one value the axis's repeats cannot explain: a frozen sensor) or ``no terms``.
    reason : str
    drift : dict or None
        The predicted drift and its check (:mod:`inertialab.workflows.imu_drift`).
    plan : dict or None
        Record lengths needed for K and for B, each within +-20 % at 95 %.
    """

    axis: str
    column: str
    kind: str
    unit: str
    deviation: object
    terms: object
    noise_density: float
    random_walk: float
    random_walk_bound: bool
    bias_instability: float
    bias_instability_bound: bool = False
    status: str = "ok"
    reason: str = ""
    drift: dict | None = None
    plan: dict | None = None
    random_walk_t_s: float | None = None
    warmup: dict | None = None  # the axis's warm-up evidence (workflows.imu_segments)
    stationarity: dict | None = None  # the segments test (noise.segments.stationarity)

    def to_dict(self) -> dict:
        si = SI_UNITS[self.kind]
        d = {"axis": self.axis, "column": self.column, "kind": self.kind,
             "unit": self.unit, "status": self.status}
        if self.reason:
            d["reason"] = self.reason
        if self.terms is not None:
            t = self.terms
            d.update({
                "noise_density": {"value": self.noise_density, "unit": si[1],
                                  "convention": "continuous",
                                  "bound": "upper" if "upper_bound" in t.N.flags else None,
                                  "ci": _si_ci(t.N.ci, _shown(t.N), self.noise_density)},
                "random_walk": {"value": self.random_walk, "unit": si[2],
                                "convention": "continuous",
                                "bound": "upper" if self.random_walk_bound else None,
                                "correlation_time_s": self.random_walk_t_s,
                                "ci": _si_ci(t.K.ci, _shown(t.K), self.random_walk)},
                "bias_instability": {"value": self.bias_instability,
                                     "unit": "rad/s" if self.kind == "gyro" else "m/s^2",
                                     "bound": "upper" if self.bias_instability_bound else None,
                                     "ci": _si_ci(t.B.ci, _shown(t.B), self.bias_instability)},
                "terms": t.to_dict(),
                "model_dev": [float(v) for v in t.model_dev(self.deviation.taus_s)]})
        if self.drift is not None:
            d["drift_prediction"] = self.drift
        if self.plan is not None:
            d["plan"] = self.plan
        if self.warmup is not None:
            d |= {"warmup_s": self.warmup["warmup_s"], "warmup": self.warmup}
        if self.stationarity is not None:
            d["stationarity"] = self.stationarity
        d["allan"] = self.deviation.to_dict() if self.deviation is not None else None
        return d


def _num(v: float) -> str:
    return "" if not np.isfinite(v) else f"{v:.4g}"


def term_text(term) -> str:
    """A term for display: ``value [low, high]``, ``<= upper`` for an upper bound,
    ``n/o`` where not observable."""
    if "not_observable" in term.flags:
        return "n/o"
    if "upper_bound" in term.flags:
        ub = term.upper_bound if np.isfinite(term.upper_bound) else term.ci[1]
        return f"<= {_num(ub)}"
    lo, hi = term.ci
    if np.isfinite(lo) and np.isfinite(hi):
        return f"{_num(term.value)} [{_num(lo)}, {_num(hi)}]"
    return _num(term.value)


def _held_text(terms) -> str:
    """The part of B's reason that says it was held to the curve's minimum
    (:mod:`inertialab.noise.terms._bounds`, flag ``held_to_curve_minimum``), else ""."""
    if terms is None or "held_to_curve_minimum" not in terms.B.flags:
        return ""
    parts = terms.B.reason.split("; ")
    i = next((k for k, p in enumerate(parts) if p.startswith("held to")), None)
    return "; ".join(parts[i:]) if i is not None else terms.B.reason


def _unit_of(axes, kind: str, name: str) -> str:
    for a in axes:
        if a.kind == kind and a.terms is not None:
            return getattr(a.terms, name).unit
    return "-"


def _shown(term) -> float:
    """The number a term shows: its bound where it is one, else its value."""
    if "upper_bound" in term.flags and np.isfinite(term.upper_bound):
        return float(term.upper_bound)
    return float(term.value)


def _si_ci(ci, value, si_value):
    """A term's interval scaled like its value into SI (None where not finite)."""
    if not (np.isfinite(value) and value > 0 and np.isfinite(si_value)):
        return None
    f = si_value / value
    return [float(c * f) if np.isfinite(c) else None for c in ci]


@dataclass(frozen=True)
class IMUNoise:
    """Six-axis noise analysis.

    Attributes
    ----------
    axes : tuple of AxisNoise (in ``gx gy gz ax ay az`` order, those present)
    rate_hz : float
    n_samples : int
    settings : dict
    """

    axes: tuple[AxisNoise, ...]
    rate_hz: float
    n_samples: int
    settings: dict = field(default_factory=dict)

    @property
    def term_confidence(self) -> float:
        """Confidence of the term intervals (the IMU default,
        ``DEFAULT_CONFIDENCE["imu"]``, when no axis has terms)."""
        return next((float(a.terms.confidence) for a in self.axes if a.terms is not None),
                    DEFAULT_CONFIDENCE["imu"])

    def axis(self, name: str) -> AxisNoise:
        for a in self.axes:
            if a.axis == name:
                return a
        raise KeyError(name)

    def sensor_value(self, kind: str, what: str) -> float:
        """Largest value over the axes of one sensor (``what``: ``noise_density`` or
        ``random_walk``), NaN when the sensor is absent."""
        vals = [getattr(a, what) for a in self.axes if a.kind == kind]
        vals = [v for v in vals if np.isfinite(v)]
        return max(vals) if vals else float("nan")

    def table(self) -> tuple[list[str], list[list]]:
        """One row per axis for display: each term with its unit in the header and its
        interval (``value [low, high]``), an upper bound as ``<= value``; the
        continuous-time densities a filter takes in SI (gyro / accelerometer units in
        the header)."""
        si = {k: SI_UNITS[k] for k in ("gyro", "accel")}
        kinds = [k for k in ("gyro", "accel") if any(a.kind == k for a in self.axes)]
        units = {name: " / ".join(_unit_of(self.axes, k, name) for k in kinds)
                 for name in ("N", "B", "K")}
        dens = " / ".join(si[k][1] for k in kinds)
        rw = " / ".join(si[k][2] for k in kinds)
        cols = ["axis", "column", "status", f"N ({units['N']})", f"B ({units['B']})",
                f"K ({units['K']})", f"noise density ({dens})", f"random walk ({rw})",
                "stationary"]
        rows = []
        for a in self.axes:
            t = a.terms
            if t is None:
                rows.append([a.axis, a.column, a.status] + [""] * 5
                            + [stationarity_text(a.stationarity)])
                continue
            n_bound = bool({"upper_bound", "not_observable"} & set(t.N.flags))
            rows.append([a.axis, a.column, a.status, term_text(t.N), term_text(t.B),
                         term_text(t.K), ("<= " if n_bound else "") + _num(a.noise_density),
                         ("<= " if a.random_walk_bound else "") + _num(a.random_walk),
                         stationarity_text(a.stationarity)])
        return cols, rows

    def notes(self) -> list[str]:
        """Lines printed under the table: every symbol, and why each axis that is not
        ``ok`` is so."""
        out = ["N white noise (angle/velocity random walk), B bias instability (flicker "
               "floor), K bias random walk; 'v [lo, hi]': value and its interval; '<= v': "
               "an upper bound (the record does not resolve the term); 'n/o': not observable "
               "(the curve holds no sign of the term, not even a bound); noise density = N "
               "and random walk = K in SI, continuous time (what Kalibr/ROS take)."]
        out += [f"{a.axis} ({a.column}) {a.status}: {a.reason}" for a in self.axes
                if a.status != "ok" and a.reason]
        out += [f"{a.axis} ({a.column}) B {held}" for a in self.axes
                if (held := _held_text(a.terms))]
        f = self.fitted_on
        if f["n_samples"] != self.n_samples:
            out.append(f"The terms are fitted on samples {f['first_sample']} to "
                       f"{f['first_sample'] + f['n_samples'] - 1} ({f['n_samples']} of "
                       f"{self.n_samples}: checked on the second half); the rest of the log "
                       "checks them. Without that check the whole log is fitted, and the numbers "
                       "differ.")
        if self.settings.get("source_note"):
            out.append("Source: " + self.settings["source_note"] + ".")
        return out

    @property
    def fitted_on(self) -> dict:
        """``{"first_sample", "n_samples"}``: the samples the terms were fitted on (the
        first half with ``--check-on half``, else the whole log)."""
        return dict(self.settings.get("fitted_on")
                    or {"first_sample": 0, "n_samples": int(self.n_samples)})

    def to_dict(self) -> dict:
        return {"rate_hz": self.rate_hz, "n_samples": self.n_samples,
                "fitted_on": self.fitted_on,
                "axes": [a.to_dict() for a in self.axes],
                "kalibr": {
                    "gyroscope_noise_density": self.sensor_value("gyro", "noise_density"),
                    "gyroscope_random_walk": self.sensor_value("gyro", "random_walk"),
                    "accelerometer_noise_density": self.sensor_value("accel", "noise_density"),
                    "accelerometer_random_walk": self.sensor_value("accel", "random_walk"),
                    "update_rate": self.rate_hz}}


def stationarity_text(d: dict | None) -> str:
    """The table's stationarity cell of an axis' segments test
    (:meth:`inertialab.noise.segments.stationarity.Stationarity.to_dict`): ``yes``, ``NO (p, tau)``
    or ``-`` (not tested)."""
    if not d or d.get("p_value") is None:
        return "-"
    if d["verdict"] == "stationary":
        return "yes"
    tau = d.get("worst_tau_s")
    at = f", {tau:g} s" if tau is not None and math.isfinite(tau) else ""
    return f"NO (p={d['p_value']:.2g}{at})"
