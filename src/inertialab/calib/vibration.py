"""The vibration-bias model of spec 001 (§3.7-3.10, §4): estimator on arrays.

:class:`VibrationRun` is one record's arrays, validated and segmented into the phases
P1 (static), P2 (vibration), P3 (static) (the workflow
:func:`inertialab.workflows.vibration.prepare` builds it from a record);
:func:`bias_targets` forms the (drive frequency, bias error) training pairs of §3.7;
:class:`VibrationModel` (model-file tag ``"vibration-compensation"``, per-type
:attr:`~VibrationModel.FORMAT_VERSION`) holds the level, the wavelet and both bias
models, RBF (§3.8) and 4th-order polynomial (§3.9), and compensates a rate with
``omega_c = A_L(omega) - vib_on g(f)`` (§3.10); :func:`residual_metrics` gives the
residual bias and edge metrics of §4. Units: rate and bias in deg/h, frequency in Hz.
No files, no records, no drawing.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from inertialab.errors import ExtrapolationWarning, InputError, NotFittedError
from inertialab.estimator import Estimator
from inertialab.io.model_schemas import check_own_payload
from inertialab.learn.poly import PolynomialRegressor
from inertialab.learn.rbf import RBFNetwork
from inertialab.noise.spectral import wavelet as wv

__all__ = ["SPREAD_GRID", "BiasTargets", "VibrationModel", "VibrationRun", "bias_targets",
           "phase_stats", "residual_metrics", "select_spread"]

#: Units of the model's inputs and outputs (model-file ``units``).
UNITS = {"f": "hz", "bias": "dph", "rate": "dph"}


@dataclass(frozen=True)
class VibrationRun:
    """One vibration-test record, validated and segmented (spec 001 §2.2).

    Attributes
    ----------
    rate_dph : ndarray (n,)
        Gyro rate in deg/h.
    vib_on : ndarray of bool (n,)
    freq_hz : ndarray (n,)
        Drive frequency (0 while off).
    fs_hz : float
    k_on, k_off : int
        First and last sample with ``vib_on = 1``.
    path, sha256 : str
        Source file and hash of its canonical columns.
    experiment : str or None
        Sidecar ``experiment`` ("sweep" / "fixed") when given.
    meta : dict
        Sidecar.
    """

    rate_dph: np.ndarray
    vib_on: np.ndarray
    freq_hz: np.ndarray
    fs_hz: float
    k_on: int
    k_off: int
    path: str = "<frame>"
    sha256: str = ""
    experiment: str | None = None
    meta: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        return int(self.rate_dph.size)

    @property
    def tau0(self) -> float:
        return 1.0 / self.fs_hz

    @property
    def p1(self) -> slice:
        return slice(0, self.k_on)

    @property
    def p2(self) -> slice:
        return slice(self.k_on, self.k_off + 1)

    @property
    def p3(self) -> slice:
        return slice(self.k_off + 1, self.n)

    def phase_slices(self) -> dict[str, slice]:
        out = {"P1": self.p1, "P2": self.p2}
        if self.k_off + 1 < self.n:
            out["P3"] = self.p3
        return out

    def guarded(self, sl: slice, guard_s: float) -> slice:
        """``sl`` without ``guard_s`` seconds at both ends."""
        g = int(round(guard_s * self.fs_hz))
        lo, hi = sl.start + g, sl.stop - g
        if hi <= lo:
            raise InputError(f"{self.path}: phase of {(sl.stop - sl.start) / self.fs_hz:g} s is "
                             f"too short for {guard_s:g}-s guards")
        return slice(lo, hi)



@dataclass(frozen=True)
class BiasTargets:
    """Bias error versus drive frequency from the sweep (spec 001 §3.7).

    Attributes
    ----------
    f_hz : ndarray
        Bin centres (Hz).
    e_dph : ndarray
        Mean bias error in each bin (deg/h).
    count : ndarray of int
        Samples per bin.
    beta_dph : float
        Static reference ``median(A_L[P1])`` (b0 plus Earth rate), deg/h.
    bin_index : ndarray of int
        Bin number ``round(f / width)`` (1, 2, ... for 1-Hz bins).
    """

    f_hz: np.ndarray
    e_dph: np.ndarray
    count: np.ndarray
    beta_dph: float
    bin_index: np.ndarray


def bias_targets(run: VibrationRun, approx: np.ndarray, *, guard_s: float = 2.0,
                 bin_width_hz: float = 1.0, min_count: int = 8, mode: str = "bins",
                 level: int = 6) -> BiasTargets:
    """Training pairs (frequency, bias error) from the sweep record (spec 001 §3.7).

    ``e_k = A_k - median(A[P1])`` for k in P2 without ``guard_s`` at both ends. With
    ``mode="bins"`` (default): 1-Hz bins ``[c - 0.5, c + 0.5)`` centred on 1, 2, ... Hz, the
    target is the bin mean, bins with fewer than ``min_count`` samples are dropped. With
    ``mode="samples"`` (the spec's option): every ``2^level``-th sample of that window.
    Frequencies stay in Hz, unscaled.
    """
    a = np.asarray(approx, dtype=float)
    beta = float(np.median(a[run.p1]))
    w = run.guarded(run.p2, guard_s)
    e = a[w] - beta
    f = run.freq_hz[w]
    if mode == "samples":
        step = 2 ** int(level)
        fs_, es_ = f[::step], e[::step]
        if fs_.size < 5:
            raise InputError(f"{run.path}: only {fs_.size} target samples at a stride of "
                             f"{step}; the bias model needs at least 5")
        return BiasTargets(f_hz=fs_, e_dph=es_, count=np.ones(fs_.size, dtype=np.int64),
                           beta_dph=beta, bin_index=np.arange(1, fs_.size + 1))
    if mode != "bins":
        raise InputError(f"targets must be 'bins' or 'samples', got {mode!r}")
    b = np.floor(f / bin_width_hz + 0.5).astype(np.int64)
    ok = b >= 1
    b, e = b[ok], e[ok]
    if b.size == 0:
        raise InputError(f"{run.path}: no vibration samples with frequency >= "
                         f"{bin_width_hz / 2:g} Hz for the bias targets")
    cnt = np.bincount(b)
    s = np.bincount(b, weights=e)
    idx = np.flatnonzero(cnt >= min_count)
    idx = idx[idx >= 1]
    if idx.size < 5:
        raise InputError(f"{run.path}: only {idx.size} frequency bins with >= {min_count} "
                         "samples; the bias model needs a sweep (at least 5 bins)")
    return BiasTargets(f_hz=idx * float(bin_width_hz), e_dph=s[idx] / cnt[idx],
                       count=cnt[idx], beta_dph=beta, bin_index=idx)




class VibrationModel(Estimator):
    """Vibration-bias compensation model (spec 001 §3.8-3.10).

    Parameters
    ----------
    level : int, default=6
        Approximation level L of the denoising ``A_L`` (seed: 6).
    wavelet : str, default="db4"
    wavelet_level : int, default=10
        J of the decomposition.
    spread, goal : float, default 1.2 and 1e-4
        RBF settings of the seed (Hz, (deg/h)^2).
    centers : str, default="max_error"
        RBF centre selection (:class:`~inertialab.learn.rbf.RBFNetwork`).
    max_neurons : int or None, default=None
    poly_degree : int, default=4
        Degree of the polynomial baseline (seed: 4).
    rng : int or None, default=0
        Seed of the ``"random_fixed"`` centre order.

    Attributes
    ----------
    rbf_ : RBFNetwork
    poly_ : PolynomialRegressor
    f_range_hz_ : (float, float)
        Training frequency range; inputs outside are clipped (and flagged).

    Examples
    --------
    A bias error ``0.3 + 0.002 f - 1e-6 f^2`` deg/h measured at 40 drive frequencies from
    20 to 400 Hz: read between them, and taken off a rate of 1 deg/h while the shaker runs
    at 150 Hz:

    >>> import numpy as np
    >>> def bias(f):
    ...     return 0.3 + 2e-3 * f - 1e-6 * f ** 2
    >>> f = np.linspace(20.0, 400.0, 40)
    >>> model = VibrationModel(spread=50.0, goal=1e-8).fit(f, bias(f))
    >>> bool(np.allclose(model.predict([100.0, 250.0]), bias(np.array([100.0, 250.0])), atol=1e-4))
    True
    >>> on = np.array([0, 0, 1, 1, 1, 1, 0, 0])
    >>> rate = 1.0 + on * bias(150.0)
    >>> bool(np.allclose(model.compensate(rate, on, np.full(8, 150.0), apply_to="raw"), 1.0,
    ...                  atol=1e-4))
    True
    """

    MODEL_TYPE = "vibration-compensation"
    #: Version of the payload written by :meth:`to_dict` (fixture
    #: ``tests/data/models/vibration-compensation-v1.json``); a payload without the key is
    #: version 1.
    FORMAT_VERSION = 1

    def __init__(self, *, level: int = 6, wavelet: str = "db4", wavelet_level: int = 10,
                 spread: float = 1.2, goal: float = 1e-4, centers: str = "max_error",
                 max_neurons: int | None = None, poly_degree: int = 4, rng=0):
        self.level = level
        self.wavelet = wavelet
        self.wavelet_level = wavelet_level
        self.spread = spread
        self.goal = goal
        self.centers = centers
        self.max_neurons = max_neurons
        self.poly_degree = poly_degree
        self.rng = rng

    def fit(self, f_hz, e_dph) -> VibrationModel:
        """Fit the RBF network and the polynomial to (frequency, bias error) pairs."""
        f = np.asarray(f_hz, dtype=float).ravel()
        e = np.asarray(e_dph, dtype=float).ravel()
        if f.size != e.size or f.size < self.poly_degree + 1:
            raise InputError(f"need matching frequency/bias pairs, at least "
                             f"{self.poly_degree + 1}; got {f.size} and {e.size}")
        self.rbf_ = RBFNetwork(spread=self.spread, goal=self.goal, centers=self.centers,
                               max_neurons=self.max_neurons, rng=self.rng).fit(f, e)
        self.poly_ = PolynomialRegressor(degree=self.poly_degree,
                                         warn_extrapolation=False).fit(f, e)
        self.f_range_hz_ = (float(f.min()), float(f.max()))
        return self

    def _check(self):
        if not hasattr(self, "rbf_"):
            raise NotFittedError("VibrationModel used before fit")

    def predict(self, f_hz, *, model: str = "rbf") -> np.ndarray:
        """Bias error (deg/h) at drive frequencies ``f_hz``; clipped to the training range
        with an :class:`~inertialab.errors.ExtrapolationWarning` when outside."""
        self._check()
        f = np.asarray(f_hz, dtype=float)
        lo, hi = self.f_range_hz_
        out_of = (f < lo) | (f > hi)
        if out_of.any():
            warnings.warn(f"{int(out_of.sum())} drive-frequency values outside the training "
                          f"range [{lo:g}, {hi:g}] Hz were clipped to it",
                          ExtrapolationWarning, stacklevel=2)
        fc = np.clip(f, lo, hi)
        u, inv = np.unique(fc.ravel(), return_inverse=True)
        if model == "rbf":
            g = self.rbf_.predict(u)
        elif model == "poly":
            g = self.poly_.predict(u)
        else:
            raise InputError(f"model must be 'rbf' or 'poly', got {model!r}")
        return g[inv].reshape(f.shape)

    def compensate(self, rate_dph, vib_on, freq_hz, *, model: str = "rbf",
                   apply_to: str = "denoised", approx=None) -> np.ndarray:
        """Compensated rate ``omega_c = A_L(omega) - vib_on g(f)`` (spec 001 eq. 8).

        ``apply_to="raw"`` subtracts ``g`` from the raw rate instead. ``approx`` may
        pass a ready ``A_L`` of ``rate_dph``.
        """
        self._check()
        x = np.asarray(rate_dph, dtype=float)
        on = np.asarray(vib_on) != 0
        if apply_to == "denoised":
            base = approx if approx is not None else wv.decompose(
                x, wavelet=self.wavelet, level=self.wavelet_level).approximation(
                    min(int(self.level), self.wavelet_level))
        elif apply_to == "raw":
            base = x
        else:
            raise InputError(f"apply_to must be 'denoised' or 'raw', got {apply_to!r}")
        g = np.zeros_like(x)
        if on.any():
            g[on] = self.predict(np.asarray(freq_hz, dtype=float)[on], model=model)
        return np.asarray(base, dtype=float) - g

    def to_dict(self) -> dict:
        self._check()
        return {
            "format_version": self.FORMAT_VERSION,
            "level": int(self.level), "wavelet": self.wavelet,
            "wavelet_level": int(self.wavelet_level), "spread": float(self.spread),
            "goal": float(self.goal), "centers": self.centers,
            "max_neurons": self.max_neurons, "poly_degree": int(self.poly_degree),
            "rng": self.rng if isinstance(self.rng, (int, type(None))) else None,
            "f_range_hz": list(self.f_range_hz_),
            "rbf": self.rbf_.to_dict(), "poly": self.poly_.to_dict(),
        }

    @classmethod
    def from_dict(cls, d: dict) -> VibrationModel:
        check_own_payload(cls.MODEL_TYPE, d)  # types, shapes, ranges: one line naming the key
        if not isinstance(d, dict):
            raise InputError("vibration-compensation model: payload is not an object")
        version = d.get("format_version", 1)
        if not isinstance(version, int) or isinstance(version, bool) or version < 1:
            raise InputError(f"vibration-compensation model: bad format_version {version!r}")
        if version > cls.FORMAT_VERSION:
            raise InputError(f"vibration-compensation model format_version {version} is newer "
                             f"than this inertialab reads ({cls.FORMAT_VERSION})")
        try:
            obj = cls(level=int(d["level"]), wavelet=str(d["wavelet"]),
                      wavelet_level=int(d["wavelet_level"]), spread=float(d["spread"]),
                      goal=float(d["goal"]), centers=str(d["centers"]),
                      max_neurons=d.get("max_neurons"), poly_degree=int(d["poly_degree"]),
                      rng=d.get("rng"))
            obj.f_range_hz_ = (float(d["f_range_hz"][0]), float(d["f_range_hz"][1]))
            obj.rbf_ = RBFNetwork.from_dict(d["rbf"])
            obj.poly_ = PolynomialRegressor.from_dict(d["poly"])
            obj.poly_.warn_extrapolation = False
        except (KeyError, TypeError, IndexError, AttributeError, ValueError) as exc:
            raise InputError(f"vibration-compensation model: missing or bad field "
                             f"({type(exc).__name__}: {exc})") from None
        return obj


def _block_std(x: np.ndarray, n_block: int) -> float:
    k = x.size // n_block
    if k < 2:
        return float("nan")
    return float(np.std(x[: k * n_block].reshape(k, n_block).mean(axis=1), ddof=1))


def residual_metrics(omega_c, run: VibrationRun, *, guard_s: float = 10.0,
                     edge_s: float = 10.0, stability_s: float = 10.0) -> dict:
    """Residual bias and edge metrics of a compensated signal (spec 001 §4), deg/h.

    ``delta_b = mean(omega_c[P2 without guard_s guards]) - mean(omega_c[P1])``; per-phase
    mean and 10-s bias stability (std of consecutive 10-s means); ``edge_on``/``edge_off``
    = ``max |omega_c - mean_P1|`` within ``edge_s`` of ``k_on`` / ``k_off``.
    """
    x = np.asarray(omega_c, dtype=float)
    m1 = float(np.mean(x[run.p1]))
    p2g = run.guarded(run.p2, guard_s)
    nb = max(1, int(round(stability_s * run.fs_hz)))
    e = int(round(edge_s * run.fs_hz))
    out = {"delta_b": float(np.mean(x[p2g])) - m1, "mean": {}, "stability_10s": {}}
    for name, sl in run.phase_slices().items():
        out["mean"][name] = float(np.mean(x[sl]))
        out["stability_10s"][name] = _block_std(x[sl], nb)
    on_win = slice(max(0, run.k_on - e), min(run.n, run.k_on + e + 1))
    off_win = slice(max(0, run.k_off - e), min(run.n, run.k_off + e + 1))
    out["edge_on"] = float(np.max(np.abs(x[on_win] - m1)))
    out["edge_off"] = float(np.max(np.abs(x[off_win] - m1)))
    return out




def phase_stats(x, run: VibrationRun, *, stability_s: float = 10.0) -> dict:
    """Bias (mean) and 10-s bias stability (std of consecutive 10-s means) of a rate per
    phase P1/P2/P3 (spec 001 §2.3 definitions), deg/h: the raw record's figures beside
    the compensated ones of :func:`residual_metrics`."""
    x = np.asarray(x, dtype=float)
    nb = max(1, int(round(stability_s * run.fs_hz)))
    out = {"bias": {}, "stability_10s": {}}
    for name, sl in run.phase_slices().items():
        out["bias"][name] = float(np.mean(x[sl]))
        out["stability_10s"][name] = _block_std(x[sl], nb)
    return out


#: Spreads (Hz) tried by :func:`select_spread` by default: the seed's 1.2 Hz and a
#: factor-of-two ladder around it up to a few bin widths.
SPREAD_GRID = (0.3, 0.6, 1.2, 2.5, 5.0, 10.0, 20.0, 40.0)


def select_spread(f_hz, e_dph, train, *, grid=SPREAD_GRID, goal: float = 1e-4,
                  centers: str = "max_error", max_neurons: int | None = None,
                  rng=0) -> dict:
    """RBF spread chosen by held-out error (spec 001 §8 "held-out tuning").

    The network is fitted on the targets where ``train`` is True (the odd 1-Hz bins in the
    workflow) and scored by the RMSE on the others; the spread with the least held-out
    RMSE wins. Returns ``{"grid", "heldout_rmse", "neurons", "chosen", "chosen_rmse"}``
    (Hz, deg/h). The seed's 1.2 Hz stays the default of the model; this is the option.
    """
    from inertialab import metrics as _metrics

    f = np.asarray(f_hz, dtype=float)
    e = np.asarray(e_dph, dtype=float)
    tr = np.asarray(train, dtype=bool)
    if tr.sum() < 5 or (~tr).sum() < 2:
        raise InputError("spread selection needs at least 5 training and 2 held-out targets")
    grid = [float(s) for s in grid]
    if not grid or any(not (np.isfinite(s) and s > 0) for s in grid):
        raise InputError("argument 'spread' grid must hold positive spreads in Hz")
    rmse, neurons = [], []
    for s in grid:
        net = RBFNetwork(spread=s, goal=goal, centers=centers, max_neurons=max_neurons,
                         rng=rng).fit(f[tr], e[tr])
        rmse.append(_metrics.rmse(e[~tr], net.predict(f[~tr])))
        neurons.append(int(net.n_neurons_))
    k = int(np.argmin(rmse))
    return {"grid": grid, "heldout_rmse": rmse, "neurons": neurons, "chosen": grid[k],
            "chosen_rmse": rmse[k]}
