"""Six IMU axes in one call, and noise parameters for Kalibr / ROS (issue 10 item 3).

:func:`analyse_imu` runs the noise core's overlapping Allan deviation
(:func:`inertialab.noise.allan.oadev`) and five-term fit
(:func:`inertialab.noise.terms.fit_noise_terms`) on gyro x/y/z and accelerometer x/y/z
of one log and returns an :class:`IMUNoise`: per axis the curve, the terms and the
two numbers visual-inertial estimators ask for, in SI units:

* **noise density** (white noise, continuous time): ``N`` of the Allan model
  ``sigma^2(tau) = N^2 / tau + ...``, i.e. ``sqrt(c_-1)``; rad/s/sqrt(Hz) for gyros,
  m/s^2/sqrt(Hz) for accelerometers. The discrete per-sample standard deviation at
  the IMU rate is ``density * sqrt(update_rate)``.
* **random walk** (bias random walk, continuous time): ``K`` of
  ``sigma^2(tau) = ... + K^2 tau / 3``, i.e. ``sqrt(3 c_1)``; rad/s^2/sqrt(Hz) and
  m/s^3/sqrt(Hz). Discrete: ``K / sqrt(update_rate)`` per sample. When the record is
  too short to show the +1/2 slope (``c_1`` not positive), the value written is
  ``sigma_hi(tau_max) sqrt(3 / tau_max)``, the rate-random-walk line through the upper
  confidence limit of the longest tau (an upper bound at that confidence), and the
  axis is flagged ``random_walk_bound``.

:func:`export_yaml` writes these as Kalibr's ``imu.yaml`` (one isotropic value per
sensor: the largest of its three axes, which is the conservative choice for an
estimator that takes one number) or as a ROS parameter file (the same keys under a
namespace, plus the per-axis values). The continuous/discrete convention is stated in
the file's comments. The CLI writes the text; this module only builds it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from inertialab import units as U
from inertialab.errors import InputError

__all__ = ["AXES", "AxisNoise", "IMUNoise", "analyse_imu", "analyse_record", "export_yaml"]

#: axis name -> (column base, kind)
AXES = {"gx": "gyro", "gy": "gyro", "gz": "gyro", "ax": "accel", "ay": "accel", "az": "accel"}

_SI = {"gyro": ("rps", "rad/s/sqrt(Hz)", "rad/s^2/sqrt(Hz)"),
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
        ``random_walk`` is an upper bound (no +1/2 slope in the record).
    bias_instability : float
        B of the five-term fit, SI (rad/s or m/s^2).
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

    def to_dict(self) -> dict:
        si = _SI[self.kind]
        return {"axis": self.axis, "column": self.column, "kind": self.kind,
                "unit": self.unit,
                "noise_density": {"value": self.noise_density, "unit": si[1],
                                  "convention": "continuous"},
                "random_walk": {"value": self.random_walk, "unit": si[2],
                                "convention": "continuous", "bound": self.random_walk_bound},
                "bias_instability": {"value": self.bias_instability,
                                     "unit": "rad/s" if self.kind == "gyro" else "m/s^2"},
                "terms": self.terms.to_dict(), "allan": self.deviation.to_dict()}


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
        """One row per axis: the figures of the JSON table (SI units)."""
        cols = ["axis", "column", "noise_density", "random_walk", "random_walk_bound",
                "bias_instability", "N", "B", "K", "N_unit", "B_unit", "K_unit"]
        rows = []
        for a in self.axes:
            t = a.terms
            rows.append([a.axis, a.column, a.noise_density, a.random_walk, a.random_walk_bound,
                         a.bias_instability, t.N.value, t.B.value, t.K.value, t.N.unit,
                         t.B.unit, t.K.unit])
        return cols, rows

    def to_dict(self) -> dict:
        return {"rate_hz": self.rate_hz, "n_samples": self.n_samples,
                "axes": [a.to_dict() for a in self.axes],
                "kalibr": {
                    "gyroscope_noise_density": self.sensor_value("gyro", "noise_density"),
                    "gyroscope_random_walk": self.sensor_value("gyro", "random_walk"),
                    "accelerometer_noise_density": self.sensor_value("accel", "noise_density"),
                    "accelerometer_random_walk": self.sensor_value("accel", "random_walk"),
                    "update_rate": self.rate_hz}}


def _axis(name: str, column: str, y, unit: str, *, rate_hz: float, taus, method: str,
          g_local: float, tau_range_s) -> AxisNoise:
    from inertialab.noise.allan import oadev
    from inertialab.noise.terms import fit_noise_terms, not_static_reason

    kind = AXES[name]
    dim = U.lookup(unit).dimension
    want = "angular_rate" if kind == "gyro" else "acceleration"
    if dim != want:
        raise InputError(f"unit '{unit}' is a {dim}, expected a {want}", column=column)
    y = np.asarray(y)
    if np.isnan(y).any():  # lost samples on the sensor's grid (analyse_record)
        from inertialab.noise.gaps import gap_deviation

        dev = gap_deviation("oadev", y, rate_hz=rate_hz, taus=taus)
    else:
        dev = oadev(y, rate_hz=rate_hz, taus=taus)
    try:
        terms = fit_noise_terms(dev, unit=unit, kind=kind, method=method, rate_hz=rate_hz,
                                tau_range_s=tau_range_s, g_local=g_local)
    except InputError as exc:
        raise InputError(str(exc), column=column) from None
    why = not_static_reason(dev.taus_s, dev.dev) if tau_range_s is None else None
    if why:
        import warnings

        from inertialab.errors import DataQualityWarning

        warnings.warn(f"column '{column}': {why}", DataQualityWarning, stacklevel=3)
    c = np.asarray(terms.coefficients, dtype=float)
    si = _SI[kind][0]
    # N^2 = c_-1 (unit^2 s): N in unit/sqrt(Hz); K^2 = 3 c_1 (unit^2 / s): K in unit*sqrt(Hz)/s
    density = (U.convert(math.sqrt(c[1]), unit, si, g_local=g_local)
               if np.isfinite(c[1]) and c[1] > 0 else float("nan"))
    if np.isfinite(c[3]) and c[3] > 0:
        rw, bound = U.convert(math.sqrt(3.0 * c[3]), unit, si, g_local=g_local), False
    else:
        tmax = float(dev.taus_s[-1])
        hi = float(dev.ci_high[-1]) if np.isfinite(dev.ci_high[-1]) else float(dev.dev[-1])
        rw = U.convert(hi * math.sqrt(3.0 / tmax), unit, si, g_local=g_local)
        bound = True
    b = (U.convert(math.sqrt(c[2]) / math.sqrt(2.0 * math.log(2.0) / math.pi), unit, si,
                   g_local=g_local) if np.isfinite(c[2]) and c[2] > 0 else float("nan"))
    return AxisNoise(axis=name, column=column, kind=kind, unit=unit, deviation=dev, terms=terms,
                     noise_density=float(density), random_walk=float(rw),
                     random_walk_bound=bound, bias_instability=float(b))


def analyse_imu(columns: dict, *, rate_hz: float, taus="octave", method: str = "wls",
                g_local: float = U.G_STANDARD, tau_range_s=None, progress=None) -> IMUNoise:
    """Noise of up to six axes.

    Parameters
    ----------
    columns : dict
        Axis (``gx gy gz ax ay az``) -> ``(column_name, samples, unit_suffix)``.
    rate_hz : float
        Sample rate, Hz (the ``update_rate`` written to Kalibr/ROS files).
    taus, method, tau_range_s
        As :func:`inertialab.noise.allan.oadev` and
        :func:`inertialab.noise.terms.fit_noise_terms` (default octave taus, "wls").
    g_local : float, default 9.80665
        Local gravity for g-based accelerometer units, m/s^2.
    """
    if not columns:
        raise InputError("no IMU axis to analyse: need gx/gy/gz and/or ax/ay/az columns")
    unknown = set(columns) - set(AXES)
    if unknown:
        raise InputError(f"unknown axes {sorted(unknown)} (known: {', '.join(AXES)})")
    out = []
    names = [a for a in AXES if a in columns]
    for i, name in enumerate(names):
        col, y, unit = columns[name]
        out.append(_axis(name, col, y, unit, rate_hz=float(rate_hz), taus=taus, method=method,
                         g_local=g_local, tau_range_s=tau_range_s))
        if progress is not None:
            progress.update(i + 1, len(names), name)
    n = int(np.asarray(columns[names[0]][1]).shape[0])
    settings = {"rate_hz": float(rate_hz), "taus": taus if isinstance(taus, (str, int)) else
                list(taus), "method": method, "g_local_mps2": float(g_local),
                "tau_range_s": None if tau_range_s is None else list(tau_range_s)}
    return IMUNoise(axes=tuple(out), rate_hz=float(rate_hz), n_samples=n, settings=settings)


def analyse_record(rec, *, rate_hz: float | None = None, taus="octave", method: str = "wls",
                   g_local: float | None = None, tau_range_s=None, progress=None) -> IMUNoise:
    """:func:`analyse_imu` on the ``gx gy gz ax ay az`` columns of a ``gyro_log`` record
    (rate from ``rate_hz``, the sidecar's ``fs_hz`` or the median step of ``t_s``)."""
    if rate_hz is None:
        from inertialab.io.preflight import preflight

        preflight(rec, "imu")  # the checks `validate --kind imu` runs
    cols = {}
    for name in AXES:
        c = rec.find(name)
        if c is not None:
            cols[name] = (c, rec.column(c), rec.units[c])
    if not cols:
        raise InputError("no IMU axis columns (gx_*, gy_*, gz_*, ax_*, ay_*, az_*); map them "
                         "with a column map (argument 'column_map')", path=rec.path)
    if "segment" in rec.data.columns and rec.data["segment"].nunique() > 1:
        raise InputError("the log has several segments (argument 'gaps' split); analyse one segment",
                         path=rec.path)
    fs, tb = rate_hz, rec.timebase  # the record's one time base (io.timestamps)
    if fs is None:
        if tb is None:
            raise InputError("needs a t_s column or argument 'rate_hz'", path=rec.path)
        fs = tb.rate_hz  # lost samples NaN on the grid (gap-resistant OADEV)
        cols = {name: (c, tb.place(y), u) for name, (c, y, u) in cols.items()}
    g = g_local if g_local is not None else float(rec.meta.get("g_local_mps2", U.G_STANDARD))
    try:
        return analyse_imu(cols, rate_hz=float(fs), taus=taus, method=method, g_local=g,
                           tau_range_s=tau_range_s, progress=progress)
    except InputError as exc:
        if exc.path is not None or rec.path is None:
            raise
        raise InputError(str(exc), path=rec.path) from None


def _fmt(v: float) -> str:
    return "null" if not np.isfinite(v) else f"{v:.6e}"


def export_yaml(result: IMUNoise, style: str = "kalibr", *, rostopic: str = "/imu0",
                namespace: str = "imu") -> str:
    """Kalibr ``imu.yaml`` or ROS parameter YAML text of an :class:`IMUNoise`.

    Both hold ``gyroscope_noise_density`` [rad/s/sqrt(Hz)], ``gyroscope_random_walk``
    [rad/s^2/sqrt(Hz)], ``accelerometer_noise_density`` [m/s^2/sqrt(Hz)],
    ``accelerometer_random_walk`` [m/s^3/sqrt(Hz)] (continuous time, the largest of the
    three axes) and ``update_rate`` [Hz]; ``ros`` nests them under ``namespace`` and
    adds the per-axis values.
    """
    if style not in ("kalibr", "ros"):
        raise InputError(f"argument 'export' must be 'kalibr' or 'ros', got '{style}'")
    d = result.to_dict()["kalibr"]
    bound = {k: any(a.random_walk_bound for a in result.axes if a.kind == k)
             for k in ("gyro", "accel")}
    head = [
        "# IMU noise parameters from inertialab (overlapping Allan deviation, five-term fit)",
        "# Continuous-time values: noise densities are white-noise spectral densities and",
        "# random walks are bias random-walk densities. Discrete-time equivalents at",
        "# update_rate: sigma_d = noise_density * sqrt(update_rate),",
        "# sigma_bd = random_walk / sqrt(update_rate).",
        "# Each value is the largest of the sensor's three axes.",
    ]
    for k, lab in (("gyro", "gyroscope"), ("accel", "accelerometer")):
        if bound[k]:
            head.append(f"# {lab}_random_walk is an upper bound: the record is too short to "
                        "show the +1/2 slope.")
    body = [
        "#Accelerometers",
        f"accelerometer_noise_density: {_fmt(d['accelerometer_noise_density'])}  # m/s^2/sqrt(Hz)",
        f"accelerometer_random_walk: {_fmt(d['accelerometer_random_walk'])}  # m/s^3/sqrt(Hz)",
        "#Gyroscopes",
        f"gyroscope_noise_density: {_fmt(d['gyroscope_noise_density'])}  # rad/s/sqrt(Hz)",
        f"gyroscope_random_walk: {_fmt(d['gyroscope_random_walk'])}  # rad/s^2/sqrt(Hz)",
    ]
    if style == "kalibr":
        body += [f"rostopic: {rostopic}", f"update_rate: {result.rate_hz:.6g}  # Hz"]
        return "\n".join(head + body) + "\n"
    lines = head + [f"{namespace}:"]
    lines += ["  " + ln if not ln.startswith("#") else "  " + ln for ln in body]
    lines.append(f"  update_rate: {result.rate_hz:.6g}  # Hz")
    lines.append("  per_axis:  # continuous time, SI")
    for a in result.axes:
        lines.append(f"    {a.axis}: {{noise_density: {_fmt(a.noise_density)}, "
                     f"random_walk: {_fmt(a.random_walk)}, "
                     f"random_walk_bound: {'true' if a.random_walk_bound else 'false'}}}")
    return "\n".join(lines) + "\n"
