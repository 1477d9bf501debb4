"""Drone-IMU thermal calibration: the ``thermal-imu`` model type, its fit on a
temperature-ramp log (:func:`fit_imu_model`), its application to a new log of the same
unit (:meth:`ThermalImuModel.correct`) and its order-3 firmware forms for PX4 and
ArduPilot.

Per sensor instance (an accelerometer or a gyro, as PX4's ``TC_A<i>``/``TC_G<i>``) and
axis, the offset is modelled against the de-quantised, lag-corrected temperature
``T + tau dT/dt`` (:mod:`inertialab.calib.thermal_imu_fit`): a polynomial whose order and
lag are chosen by held-out cross-validation (``method="poly"``), or the study's ANFIS
(spec 000 §3.4, ``"scm-anfis"``; ``"iafsa-scm-anfis"`` with the fish-swarm search of
§3.5) on the inputs ``(T, dT/dt)``, which learns the lag itself (spec 000 §8.4,
transients). A gyro's offset is absolute (subtracted as a whole); an accelerometer's is
relative to its value at the middle of the range, as PX4's script takes it relative to
the median, because gravity and the ordinary accelerometer calibration set the constant.

The PX4 file must be a cubic in the *reported* temperature about TREF. Three cubic forms
of the model are candidates: ``static`` (the model at dT/dt = 0 on a uniform grid),
``as-logged`` (the model's offsets along the log against the reported temperature, so
the average lag of the ramp is folded in) and ``direct`` (the binned data against the
reported temperature). Per axis the form kept is the one with the lowest held-out
residual when each fold's model builds the forms and the firmware's formula (clamped)
meets the left-out bins (:func:`inertialab.calib.thermal_imu_fit.folds`); that residual
is written into the files.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field, fields

import numpy as np

from inertialab.calib import thermal_imu_fit as tf
from inertialab.errors import InputError
from inertialab.io.model_schemas import check_own_payload

__all__ = ["AXES", "FORMS", "METHODS", "FitSettings", "ImuFit", "ThermalImuModel",
           "fit_imu_model"]

METHODS = ("poly", "scm-anfis", "iafsa-scm-anfis")
AXES = {"accel": ("ax", "ay", "az"), "gyro": ("gx", "gy", "gz")}
UNITS = {"accel": "m/s^2", "gyro": "rad/s"}
FORMS = ("static", "as-logged", "direct")


@dataclass(frozen=True)
class FitSettings:
    """Settings of the fit: ``method`` (:data:`METHODS`), ``bin_s`` (5 s), ``max_order``
    (7), ``min_span_c`` (10 °C: ArduPilot's learner needs the same), ``n_blocks`` (6
    temperature blocks), ANFIS ``epochs`` (50), IAFSA ``fish``/``generations`` (5/5:
    a small search, each objective call is a 20-epoch ANFIS) and ``seed``."""

    method: str = "poly"
    bin_s: float = 5.0
    max_order: int = 7
    min_span_c: float = 10.0
    n_blocks: int = 6
    epochs: int = 50
    fish: int = 5
    generations: int = 5
    seed: int = 0

    @classmethod
    def of(cls, settings=None) -> FitSettings:
        """The validated settings of ``settings``: any object with these attribute names
        (a command's Config, e.g. ``thermal fit``'s, whose flags ``--method``,
        ``--epochs``, ``--fish``, ``--generations`` and ``--seed`` are these names); an
        attribute it lacks (or None for all) takes the default above."""
        if not isinstance(settings, cls):
            settings = cls(**{f.name: getattr(settings, f.name) for f in fields(cls)
                              if hasattr(settings, f.name)})
        return settings.validate()

    def validate(self) -> FitSettings:
        """``self`` when ``method``, ``bin_s`` and ``max_order`` are valid; else one-line
        :class:`InputError` naming the argument."""
        if self.method not in METHODS:
            raise InputError(f"argument 'method' must be one of {', '.join(METHODS)}, got "
                             f"'{self.method}'")
        if not 0.1 <= self.bin_s <= 600 or not 1 <= self.max_order <= 9:
            raise InputError("argument 'bin_s' must be in [0.1, 600] s and 'max_order' 1..9")
        return self


# ----------------------------------------------------------------------- the model

class ThermalImuModel:
    """Temperature model of every sensor instance of one board (module docstring).

    ``sensors``: one dict per stream with ``kind``, ``instance``, ``device_id``,
    ``t_min``/``t_max`` (calibrated range of the reported temperature, °C), ``t_ref``
    (its middle), ``center``/``half`` (the polynomial's scaling), ``sigma_s``/``bin_s``
    (de-quantisation), ``dtdt_range`` (°C/s), ``relative``, coverage figures and
    ``axes`` (three dicts: ``axis``, ``order``, ``tau_s``, ``coef``, ``anfis`` payload or
    None, ``offset_ref``, residuals, hysteresis) and ``px4`` (the chosen cubic ``x``
    (4 x 3), ``forms`` per axis and their held-out ``form_rms``).
    """

    MODEL_TYPE = "thermal-imu"
    FORMAT_VERSION = 1

    def __init__(self, *, method: str, sensors: list, source: str = ""):
        self.method = method
        self.sensors = sensors
        self.source = source
        self._anfis = {}

    def to_dict(self) -> dict:
        return {"method": self.method, "source": self.source,
                "sensors": copy.deepcopy(self.sensors)}

    @classmethod
    def from_dict(cls, d: dict) -> ThermalImuModel:
        check_own_payload(cls.MODEL_TYPE, d)  # types, shapes, ranges: one line naming the key
        try:
            sensors = d["sensors"]
            for s in sensors:
                if s["kind"] not in AXES or len(s["axes"]) != 3 or \
                        not s["t_min"] < s["t_max"]:
                    raise InputError("a sensor entry of the thermal-imu model is malformed")
            return cls(method=str(d["method"]), sensors=copy.deepcopy(sensors),
                       source=str(d.get("source", "")))
        except (KeyError, TypeError) as exc:
            raise InputError(f"thermal-imu model payload lacks {exc}") from None

    def sensor(self, kind: str, instance: int) -> dict:
        for s in self.sensors:
            if s["kind"] == kind and s["instance"] == instance:
                return s
        raise InputError(f"the model has no {kind} {instance}")

    def _regressor(self, s: dict, a: int):
        key = (s["kind"], s["instance"], a)
        if key not in self._anfis:
            from inertialab.learn.anfis import ANFIS

            self._anfis[key] = ANFIS.from_dict(s["axes"][a]["anfis"])
        return self._anfis[key]

    def axis_offset(self, s: dict, a: int, temp, dtdt) -> np.ndarray:
        """Offset of axis ``a`` of sensor ``s`` at smoothed temperature ``temp`` (°C) and
        slope ``dtdt`` (°C/s): the temperature, and ``T + tau dT/dt``, clamped to the
        calibrated range (an ANFIS's slope input to its training range too)."""
        ax = s["axes"][a]
        temp = np.clip(np.asarray(temp, float), s["t_min"], s["t_max"])
        dtdt = np.asarray(dtdt, float)
        if ax.get("anfis") is not None:  # inputs kept inside the ANFIS's training box
            dtdt = np.clip(dtdt, *s["dtdt_range"])
            return self._regressor(s, a).predict(np.column_stack([temp, dtdt]))
        t_eff = np.clip(temp + ax["tau_s"] * dtdt, s["t_min"], s["t_max"])
        return tf.vander(t_eff, s["center"], s["half"], ax["order"]) @ np.asarray(ax["coef"])

    def px4_sensors(self) -> list:
        """The sensors as :func:`inertialab.export.thermal_params.px4_text` takes
        them (TC slot = the instance; PX4 matches the device id)."""
        return [{"kind": s["kind"], "slot": s["instance"], "device_id": s["device_id"],
                 "t_ref": s["t_ref"], "t_min": s["t_min"], "t_max": s["t_max"],
                 "x": np.asarray(s["px4"]["x"])} for s in self.sensors]

    def ardupilot_sensors(self, *, caltemp_c: float | None = None) -> list:
        """One dict per IMU for :func:`~inertialab.export.thermal_params.
        ardupilot_text`: the PX4 cubic re-expanded about ArduPilot's fixed 35 °C, its
        constant dropped (the firmware's correction is relative to the calibration
        temperature); the range is the union of the IMU's accel and gyro ranges."""
        from numpy.polynomial import Polynomial

        out = {}
        for s in self.sensors:
            d = out.setdefault(s["instance"], {"imu": s["instance"] + 1, "t_min": s["t_min"],
                                               "t_max": s["t_max"], "accel": np.zeros((3, 3)),
                                               "gyro": np.zeros((3, 3)),
                                               "accel_caltemp": caltemp_c,
                                               "gyro_caltemp": caltemp_c})
            d["t_min"], d["t_max"] = min(d["t_min"], s["t_min"]), max(d["t_max"], s["t_max"])
            x = np.asarray(s["px4"]["x"])
            shift = Polynomial([35.0 - s["t_ref"], 1.0])
            for a in range(3):
                c = Polynomial(x[:, a])(shift).coef
                d[s["kind"]][:, a] = np.pad(c, (0, 4 - c.size))[1:4]
        return [out[k] for k in sorted(out)]

    def residual_notes(self) -> list:
        """One comment line per sensor: the held-out RMS of the model and of the order-3
        form the files carry, per axis (reading units)."""
        lines = []
        for s in self.sensors:
            parts = [f"{ax['axis']} model {ax['rms_cv']:.3g}, order-3 "
                     f"{ax['form_rms'][f]:.3g} ({f})"
                     for ax, f in zip(s["axes"], s["px4"]["forms"])]
            lines.append(f"{s['kind']} {s['instance']} (device {s['device_id']}), held-out RMS "
                         f"in {UNITS[s['kind']]}: " + "; ".join(parts))
        return lines

    def axis_scale(self, s: dict, a: int, temp, dtdt) -> np.ndarray:
        """Scale-factor error of axis ``a`` (dimensionless; 0 where none was fitted) at
        ``T + tau dT/dt`` clamped to the calibrated range."""
        ax = s["axes"][a]
        temp = np.asarray(temp, float)
        if ax.get("scale") is None:
            return np.zeros(temp.shape)
        t_eff = np.clip(np.clip(temp, s["t_min"], s["t_max"]) + ax["tau_s"] * np.asarray(
            dtdt, float), s["t_min"], s["t_max"])
        return tf.vander(t_eff, s["center"], s["half"], len(ax["scale"]) - 1) @ \
            np.asarray(ax["scale"])

    def axis_reading(self, s: dict, a: int, temp, dtdt, grav=None) -> np.ndarray:
        """The model's reading of axis ``a`` less the nominal gravity ``grav`` (0: none):
        offset plus scale error times ``grav``."""
        out = self.axis_offset(s, a, temp, dtdt)
        return out if grav is None else out + self.axis_scale(s, a, temp, dtdt) * grav

    def correct(self, s: dict, t_s, temp_c, values):
        """The readings ``values`` (n, 3) of sensor ``s`` corrected; returns ``(corrected,
        n_outside)`` with ``n_outside`` the samples whose reported temperature lies outside
        the calibrated range (the model's temperature is clamped there, as the firmware
        clamps)."""
        t_s = np.asarray(t_s, float)
        b = tf.bin_stream(t_s, temp_c, np.asarray(values, float), bin_s=s["bin_s"],
                          sigma_s=s["sigma_s"])
        temp = np.interp(t_s, b.t, b.temp)
        dtdt = np.interp(t_s, b.t, b.dtdt)
        reported = np.asarray(temp_c, float)
        outside = int(np.sum((reported < s["t_min"]) | (reported > s["t_max"])))
        out = np.array(values, float, copy=True)
        for a in range(3):
            out[:, a] -= self.axis_offset(s, a, temp, dtdt) - s["axes"][a]["offset_ref"]
            out[:, a] /= 1.0 + self.axis_scale(s, a, temp, dtdt)
        return out, outside


# --------------------------------------------------------------------------- fitting

@dataclass
class ImuFit:
    """The fit of one log: ``model``, and per sensor its bins (``binned``, for the
    figures) and the residuals of the final model on them (``resid``); ``settings``: the
    :class:`FitSettings` it ran with."""

    model: ThermalImuModel
    binned: dict = field(default_factory=dict)
    resid: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    settings: FitSettings | None = None


def _anfis_axis(X, y, settings: FitSettings, rng):
    from inertialab.learn.anfis import ANFIS

    bx = np.vstack([X.min(axis=0), X.max(axis=0)])
    by = (float(y.min()), float(y.max()))
    idx = rng.permutation(y.size)
    va, fi = np.sort(idx[: y.size // 5]), np.sort(idx[y.size // 5:])
    params = {}
    if settings.method == "iafsa-scm-anfis":
        from inertialab.learn.scm_search import search_scm
        from inertialab.optim.fish_swarm import iafsa

        params = search_scm(X[fi], y[fi], X[va], y[va], k1=1.0, bounds_x=bx, bounds_y=by,
                            optimizer=iafsa, fish=settings.fish,
                            generations=settings.generations, rng=rng).params
    return ANFIS(epochs=settings.epochs, input_bounds=bx, output_bounds=by, **params).fit(
        X[fi], y[fi], validation=(X[va], y[va]))


def _anfis_cv(b, a, fold_list, settings, rng) -> float:
    X = np.column_stack([b.temp, b.dtdt])
    sse, cnt = 0.0, 0
    for _, tr, te in fold_list:
        m = _anfis_axis(X[tr], b.y[tr, a], settings, rng)
        r = b.y[te, a] - m.predict(X[te])
        sse += float(r @ r)
        cnt += int(te.sum())
    return float(np.sqrt(sse / max(cnt, 1)))


def _cubic(dt, v):
    """Least-squares cubic coefficients X0..X3 of ``v`` in ``dt``."""
    return np.linalg.lstsq(np.vander(dt, 4, increasing=True), v, rcond=None)[0]


def _forms(model: ThermalImuModel, s: dict, a: int, b, t_ref: float) -> dict:
    """The three cubic candidates of axis ``a`` (module docstring) about ``t_ref``."""
    grid = np.linspace(s["t_min"], s["t_max"], 241)
    ref = s["axes"][a]["offset_ref"]
    static = model.axis_offset(s, a, grid, np.zeros_like(grid)) - ref
    logged = model.axis_offset(s, a, b.temp, b.dtdt) - ref
    return {"static": _cubic(grid - t_ref, static),
            "as-logged": _cubic(b.temp_raw - t_ref, logged),
            "direct": _cubic(b.temp_raw - t_ref, b.y[:, a] - ref)}


def _firmware(x, temp, s: dict, t_ref: float) -> np.ndarray:
    d = np.clip(temp, s["t_min"], s["t_max"]) - t_ref
    return np.polynomial.polynomial.polyval(d, x)


def _sensor_axes(b, choices, settings: FitSettings, rng, base: dict) -> dict:
    """A sensor dict fitted on the bins ``b`` with the chosen orders and lags (poly) or
    the configured ANFIS; ``base`` gives kind, instance and device id."""
    t_min, t_max = base.get("t_min", float(b.temp_raw.min())), base.get("t_max",
                                                                        float(b.temp_raw.max()))
    s = dict(base, t_min=t_min, t_max=t_max, t_ref=0.5 * (t_min + t_max),
             center=0.5 * (t_min + t_max), half=max(0.5 * (t_max - t_min), 1e-6),
             dtdt_range=[float(b.dtdt.min()), float(b.dtdt.max())],
             sigma_s=b.sigma_s, bin_s=b.bin_s, axes=[])
    X = np.column_stack([b.temp, b.dtdt])
    for a, ch in enumerate(choices):
        t_eff = b.temp + ch.tau_s * b.dtdt
        V = tf.vander(t_eff, s["center"], s["half"], ch.order)
        if ch.scale_coef is not None:
            V = np.hstack([V, tf.scale_columns(b, a, t_eff, s["center"], s["half"])])
        c = np.linalg.lstsq(V, b.y[:, a], rcond=None)[0]
        ax = {"axis": AXES[s["kind"]][a], "order": ch.order, "tau_s": ch.tau_s,
              "coef": c[:ch.order + 1].tolist(), "anfis": None, "offset_ref": 0.0,
              "scale": None if ch.scale_coef is None else c[ch.order + 1:].tolist()}
        if settings.method != "poly" and ch.scale_coef is None:
            ax["anfis"] = _anfis_axis(X, b.y[:, a], settings, rng).to_dict()
        s["axes"].append(ax)
    m = ThermalImuModel(method=settings.method, sensors=[s])
    if s["relative"]:  # a scaled axis's offset is absolute (opposite faces tell it)
        for a in range(3):
            if s["axes"][a]["scale"] is None:
                s["axes"][a]["offset_ref"] = float(m.axis_offset(s, a, [s["t_ref"]], [0.0])[0])
    return s


def _held_out(b, fl, choices, settings, rng, base) -> tuple:
    """Per fold, the sensor refitted on the training bins: the held-out RMS of the model
    (n_axes,) and of each cubic form (forms x axes) under the firmware's clamped formula."""
    sse_m, sse_f, cnt = np.zeros(3), np.zeros((len(FORMS), 3)), 0
    for _, tr, te in fl:
        sub = tf.subset(b, tr)
        s = _sensor_axes(sub, choices, settings, rng, base)
        m = ThermalImuModel(method=settings.method, sensors=[s])
        for a in range(3):
            ref = s["axes"][a]["offset_ref"]
            y = b.y[te, a] - ref
            grav = None if b.grav is None else b.grav[te, a]
            r = y - (m.axis_reading(s, a, b.temp[te], b.dtdt[te], grav) - ref)
            sse_m[a] += float(r @ r)
            forms = _forms(m, s, a, sub, s["t_ref"])
            for k, name in enumerate(FORMS):
                r = y - _firmware(forms[name], b.temp_raw[te], s, s["t_ref"])
                sse_f[k, a] += float(r @ r)
        cnt += int(te.sum())
    return np.sqrt(sse_m / max(cnt, 1)), np.sqrt(sse_f / max(cnt, 1))


def _fit_sensor(stream, settings: FitSettings, rng):
    span = float(np.ptp(stream.temp_c))
    if span < settings.min_span_c:
        raise InputError(f"{stream.name}: the temperature spans only {span:.1f} °C "
                         f"({np.min(stream.temp_c):.1f} to {np.max(stream.temp_c):.1f} °C); "
                         f"a thermal fit needs at least {settings.min_span_c:g} °C")
    b = tf.bin_stream(stream.t_s, stream.temp_c, stream.values, bin_s=settings.bin_s)
    scaled = np.zeros(3, bool)
    if stream.kind == "accel":
        b, scaled = tf.with_orientations(b)
    fl = tf.folds(b, settings.n_blocks)
    t_min, t_max = float(b.temp_raw.min()), float(b.temp_raw.max())
    choices = tf.select_axes(b, fl, center=0.5 * (t_min + t_max), half=0.5 * (t_max - t_min),
                             max_order=settings.max_order, scaled=scaled)
    base = {"kind": stream.kind, "instance": stream.instance, "device_id": stream.device_id,
            "relative": stream.kind == "accel"}
    # the calibrated range: the reported extremes, as PX4's script takes TMIN/TMAX
    s = _sensor_axes(b, choices, settings, rng, dict(base, t_min=float(np.min(stream.temp_c)),
                                                     t_max=float(np.max(stream.temp_c))))
    m = ThermalImuModel(method=settings.method, sensors=[s])
    cv_model, cv_forms = _held_out(b, fl, choices, settings, rng, base)
    resid = np.column_stack([b.y[:, a] - m.axis_reading(
        s, a, b.temp, b.dtdt, None if b.grav is None else b.grav[:, a]) for a in range(3)])
    x = np.zeros((4, 3))
    chosen = []
    for a, ax in enumerate(s["axes"]):
        forms = _forms(m, s, a, b, s["t_ref"])
        k = int(np.argmin(cv_forms[:, a]))
        chosen.append(FORMS[k])
        x[:, a] = forms[FORMS[k]]
        V0 = tf.vander(b.temp, s["center"], s["half"], ax["order"])
        if ax["scale"] is not None:
            V0 = np.hstack([V0, tf.scale_columns(b, a, b.temp, s["center"], s["half"])])
        r0 = b.y[:, a] - V0 @ np.linalg.lstsq(V0, b.y[:, a], rcond=None)[0]
        h = tf.hysteresis(b, resid[:, a])
        h0 = tf.hysteresis(b, r0)
        ax.update(rms_in=float(np.sqrt(np.mean(resid[:, a] ** 2))),
                  rms_cv=float(cv_model[a]), hysteresis=h, hysteresis_tau0=h0,
                  form_rms={n: float(cv_forms[k2, a]) for k2, n in enumerate(FORMS)})
    s.update(n_samples=int(stream.t_s.size), span_c=span,
             samples_per_c=float(stream.t_s.size / span),
             px4={"forms": chosen, "x": x.tolist()})
    return s, b, resid


def fit_imu_model(log, settings=None) -> ImuFit:
    """Fit every sensor stream of ``log`` (an
    :class:`~inertialab.io.formats.thermal_logs.ImuThermalLog`) with ``settings``: a
    :class:`FitSettings` or any object with its attribute names, read by those names (a
    command's Config; :meth:`FitSettings.of`). One-line :class:`InputError` naming the
    argument for a bad setting, or the instance for a span under ``min_span_c``."""
    st = FitSettings.of(settings)
    rng = np.random.default_rng(st.seed)
    sensors, fit = [], ImuFit(model=None, settings=st)
    for stream in log.streams:
        s, b, resid = _fit_sensor(stream, st, rng)
        sensors.append(s)
        fit.binned[(s["kind"], s["instance"])] = b
        fit.resid[(s["kind"], s["instance"])] = resid
    fit.model = ThermalImuModel(method=st.method, sensors=sensors, source=log.source)
    return fit
