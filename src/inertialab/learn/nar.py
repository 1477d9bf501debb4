"""NAR forecaster: tapped-delay-line tanh network, open-loop LM training, closed-loop forecasts.

The MATLAB ``narnet`` workflow of spec 004 §3, per series:

1. order p by kernel CV (:func:`~inertialab.learn.order_cv.select_order_cv`) unless given;
2. the series mapped to [-1, 1] with its in-sample min/max (``mapminmax``, §3.3);
3. open-loop samples (u_i = the p observed previous values, target y_i; §3.4);
4. R restarts of :class:`~inertialab.learn.mlp_lm.MLPRegressorLM` (Nguyen-Widrow,
   trainlm, 90/10 split, validation early stopping), each with its own child seed
   ``SeedSequence(seed).spawn(R)`` (§3.7);
5. residual whiteness check of every member (§3.9, :func:`whiteness`);
6. ``combine="best"`` (preset ``paper``) or the pointwise ``"median"`` / ``"mean"`` of
   the ceil(R/2) best members (preset ``strict``);
7. recursive closed-loop forecasts from the last p observations (§3.8) and 95 %
   intervals from B = 200 residual-bootstrap paths per retained member (§3.10).

Every member's child seed spawns two streams in this order: training (split
permutation, then weights) and forecast paths.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from inertialab import metrics
from inertialab.errors import DataQualityWarning, ExtrapolationWarning, InputError, NotFittedError
from inertialab.estimator import Estimator
from inertialab.io.model_schemas import check_own_payload
from inertialab.learn.forecast_baselines import Forecast
from inertialab.learn.mlp_lm import MLPRegressorLM, forward, n_params
from inertialab.learn.order_cv import OrderSelection, select_order_cv
from inertialab.limits import bounded_int, finite

__all__ = ["AUTO_H_MAX", "PRESETS", "SPEC_H", "NARForecaster", "Whiteness", "auto_lag_bound",
           "whiteness"]

#: preset -> (combine, split) defaults (spec 004 §3.4, §3.7)
PRESETS = {"paper": ("best", "random"), "strict": ("median", "block")}

#: Spec 004 §3.1 lag bound H = 6 [R-2] (the study's value) and the cap of ``H="auto"``.
SPEC_H = 6
AUTO_H_MAX = 40

#: Largest lag order a NAR model may have (a storage programme has a few hundred days).
MAX_ORDER = 1000


def auto_lag_bound(n: int) -> int:
    """Lag bound of the learner's generic default ``H="auto"`` for ``n`` usable values.

    Spec 004 §3.1 fixes H = 6 [R-2: not in the seed, a free parameter of low confidence]
    and requires m >= 10 H CV targets, m = n - H. ``"auto"`` takes the largest bound that
    requirement allows, H = floor(n / 11), never below the spec's 6 and at most
    ``AUTO_H_MAX`` = 40 (the CV costs O(H m^2)). A 100-day record keeps H = 9 or less;
    a 500-value series gets H = 40, so the kernel CV finds its own minimum instead of the
    bound's: on Mackey-Glass (tau = 17, 500 values) CV(p) has a local minimum at p = 5
    and its global one at p = 23-26, and H = 6 stops at the local one (benchmarks/drift.py).
    """
    return int(max(SPEC_H, min(AUTO_H_MAX, int(n) // 11)))


@dataclass(frozen=True)
class Whiteness:
    """Residual whiteness check of spec 004 §3.9.

    Attributes
    ----------
    acf : r_k, k = 1..L
    bound : 1.96 / sqrt(Q)
    violations : number of |r_k| > bound
    allowed : floor(0.1 L)
    ljung_box_p : p-value of the Ljung-Box test at lag min(10, Q-1), model_df = 0
    passed : violations <= allowed and ljung_box_p >= 0.01
    """

    acf: tuple
    bound: float
    violations: int
    allowed: int
    ljung_box_p: float
    passed: bool

    def to_dict(self) -> dict:
        return {"acf": list(self.acf), "bound": self.bound, "violations": self.violations,
                "allowed": self.allowed, "ljung_box_p": self.ljung_box_p,
                "passed": self.passed}


def whiteness(e, *, max_lag: int = 20, lb_lag: int = 10, alpha_lb: float = 0.01) -> Whiteness:
    """Residual autocorrelation and Ljung-Box check (spec 004 §3.9).

    r_k = sum_{i<=Q-k} (e_i - mean)(e_{i+k} - mean) / sum (e_i - mean)^2, k = 1..L,
    L = min(max_lag, Q - 1); pass if at most floor(0.1 L) |r_k| exceed 1.96/sqrt(Q) and the
    Ljung-Box p-value (``statsmodels.stats.diagnostic.acorr_ljungbox``) at lag
    ``lb_lag`` is >= ``alpha_lb``.
    """
    from statsmodels.stats.diagnostic import acorr_ljungbox

    e = np.asarray(e, dtype=float).ravel()
    Q = e.size
    if Q < 3:
        raise InputError(f"need at least 3 residuals for a whiteness check, got {Q}")
    L = min(int(max_lag), Q - 1)
    d = e - e.mean()
    den = float(np.sum(d * d))
    if den == 0.0:
        acf = np.zeros(L)
    else:
        acf = np.array([np.sum(d[: Q - k] * d[k:]) / den for k in range(1, L + 1)])
    bound = 1.96 / math.sqrt(Q)
    viol = int(np.sum(np.abs(acf) > bound))
    allowed = int(math.floor(0.1 * L))
    if den == 0.0:
        p = 1.0
    else:
        lag = min(int(lb_lag), Q - 1)
        p = float(np.asarray(acorr_ljungbox(e, lags=[lag], model_df=0)["lb_pvalue"])[0])
    return Whiteness(tuple(float(a) for a in acf), bound, viol, allowed, p,
                     bool(viol <= allowed and p >= alpha_lb))


def _seed_sequence(rng) -> np.random.SeedSequence:
    if isinstance(rng, np.random.SeedSequence):
        return rng
    if isinstance(rng, np.random.Generator):
        return np.random.SeedSequence(int(rng.integers(0, 2**63)))
    if rng is None:
        return np.random.SeedSequence(0)
    return np.random.SeedSequence(int(rng))


@dataclass
class _Member:
    theta: np.ndarray
    val_mse: float
    train_mse: float
    resid: np.ndarray        # normalised one-step residuals, all Q samples (y~ - y~hat)
    fitted: np.ndarray       # normalised one-step predictions, all Q samples
    whiteness: Whiteness
    max_ae: float            # in-sample max |error|, original units
    accepted: bool
    stop_reason: str
    epochs: int
    path_seed: np.random.SeedSequence
    val_mask: np.ndarray     # which of the Q samples were validation


class NARForecaster(Estimator):
    """Nonlinear autoregressive network forecaster (spec 004 §3).

    Parameters
    ----------
    order : int, optional
        Lag order p; ``None`` = kernel-CV selection (§3.1) with ``H``, ``c``, ``bandwidth``.
    H : int or "auto", default="auto"
        Upper bound of the order search. ``"auto"`` = :func:`auto_lag_bound` of the
        number of usable values (6 for short records, up to 40 for long series); the
        spec 004 study passes the spec's H = 6 (§3.1 [R-2], ``workflows.drift.FitConfig.H``).
    c : float, default=0.5
        Bandwidth constant of the order search.
    bandwidth : {"rule", "cv"}, default="rule"
    hidden : int, default=10
        Hidden neurons S [R-3].
    hidden_grid : sequence of int, optional
        Choose S from these sizes by the mean validation MSE of the R restarts (spec 004
        §3.2 option ``hidden_grid``, e.g. (2, 4, 6, 8, 10)); every size trains from the
        same R child seeds; ties go to the smaller size. Overrides ``hidden``.
    restarts : int, default=10
        R (§3.7).
    preset : {"paper", "strict"}, default="paper"
        Defaults for ``combine`` and ``split``: paper = ("best", "random"),
        strict = ("median", "block").
    combine : {"best", "median", "mean"}, optional
        Overrides the preset.
    split : {"random", "block"}, optional
        Overrides the preset.
    val_fraction : float, default=0.1
    n_paths : int, default=200
        Bootstrap paths per retained member for the intervals (§3.10).
    tol_fit : float, optional
        Acceptance bound on the in-sample max |error| (original units).
    lm : dict, optional
        Extra :class:`MLPRegressorLM` settings (``max_epochs``, ``mu``, ``max_fail`` ...).
    rng : int | Generator | SeedSequence | None, default=None (= seed 0)

    Attributes
    ----------
    order_ : p used; ``order_selection_`` : :class:`OrderSelection` or None
    hidden_ : S used; ``hidden_scores_`` : {S: mean validation MSE} when a grid was searched
    members_ : trained restarts; ``chosen_`` : indices of the retained members
    accepted_ : whether the retained members passed the acceptance checks
    sample_index_ : (Q,) target indices of the open-loop samples
    fitted_ : (Q,) combined one-step predictions (original units)
    whiteness_ : :class:`Whiteness` of the combined one-step residuals
    constant_ : True when the series was constant (model = persistence)

    Examples
    --------
    An AR(2) series ``y_k = 0.9 y_(k-1) - 0.2 y_(k-2) + 0.1 + e_k`` (noise sd 0.01): the
    forecast follows the series' exact conditional mean, which its 95 % band holds:

    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> y, e = np.zeros(80), rng.normal(0.0, 0.01, 80)
    >>> for k in range(2, 80):
    ...     y[k] = 0.9 * y[k - 1] - 0.2 * y[k - 2] + 0.1 + e[k]
    >>> exact, (a, b) = [], (y[-1], y[-2])
    >>> for _ in range(3):
    ...     a, b = 0.9 * a - 0.2 * b + 0.1, a
    ...     exact.append(a)
    >>> nar = NARForecaster(order=2, hidden=2, restarts=1, n_paths=20, rng=0).fit(y)
    >>> fc = nar.forecast(3)
    >>> bool(np.all(np.abs(fc.values - exact) < 0.02))
    True
    >>> bool(np.all((fc.lo95 < exact) & (exact < fc.hi95)))
    True
    """

    MODEL_TYPE = "nar"

    def __init__(self, *, order=None, H="auto", c=0.5, bandwidth="rule", hidden=10, restarts=10,
                 preset="paper", combine=None, split=None, val_fraction=0.1, n_paths=200,
                 tol_fit=None, lm=None, rng=None, hidden_grid=None):
        self.order = order
        self.H = H
        self.c = c
        self.bandwidth = bandwidth
        self.hidden = hidden
        self.restarts = restarts
        self.preset = preset
        self.combine = combine
        self.split = split
        self.val_fraction = val_fraction
        self.n_paths = n_paths
        self.tol_fit = tol_fit
        self.lm = lm
        self.rng = rng
        self.hidden_grid = hidden_grid

    # ------------------------------------------------------------------------- helpers
    def _settings(self):
        if self.preset not in PRESETS:
            raise InputError(f"preset must be one of {', '.join(PRESETS)}, got {self.preset!r}")
        comb, split = PRESETS[self.preset]
        comb = self.combine or comb
        split = self.split or split
        if comb not in ("best", "median", "mean"):
            raise InputError(f"combine must be best, median or mean, got {comb!r}")
        return comb, split

    def _to_unit(self, y):
        if self.span_ == 0.0:
            return np.zeros_like(np.asarray(y, dtype=float))
        return 2.0 * (np.asarray(y, dtype=float) - self.lo_) / self.span_ - 1.0

    def _from_unit(self, z):
        return (np.asarray(z) + 1.0) * self.span_ / 2.0 + self.lo_

    def _lag_bound(self, n_usable: int) -> int:
        if isinstance(self.H, str):
            if self.H != "auto":
                raise InputError(f"argument 'H' must be a positive integer or 'auto', got {self.H!r}")
            return auto_lag_bound(n_usable)
        return int(self.H)

    def _hidden_sizes(self) -> list:
        if self.hidden_grid is None:
            return [int(self.hidden)]
        try:
            sizes = sorted({int(v) for v in self.hidden_grid})
        except (TypeError, ValueError):
            raise InputError(f"hidden_grid must be positive integers, got {self.hidden_grid!r}") from None
        if not sizes or sizes[0] < 1 or sizes[-1] > 200:
            raise InputError(f"hidden_grid must be integers from 1 to 200, got {self.hidden_grid!r}")
        if not float(self.val_fraction) > 0:
            raise InputError("hidden_grid needs a validation split (val_fraction > 0)")
        return sizes

    def _train_members(self, U, tgt, S, streams, split, lm) -> list:
        """R restarts of an S-neuron net from the (training, paths) seed pairs (§3.5-3.7)."""
        members = []
        for s_train, s_paths in streams:
            net = MLPRegressorLM(hidden=int(S), scale=False, split=split,
                                 val_fraction=float(self.val_fraction),
                                 rng=np.random.Generator(np.random.PCG64(s_train)), **lm)
            net.fit(U, tgt)
            theta = net.theta_
            fit_n = forward(theta, U, int(S))
            res = tgt - fit_n
            rep = net.report_
            vm = min(rep.val_mse) if rep.val_mse else rep.train_mse[-1]
            val_mask = np.zeros(tgt.size, dtype=bool)
            val_mask[net.val_index_] = True
            wh = whiteness(res * self.span_ / 2.0)
            max_ae = float(np.max(np.abs(res))) * self.span_ / 2.0
            acc = wh.passed and (self.tol_fit is None or max_ae <= float(self.tol_fit))
            members.append(_Member(theta, float(vm), float(np.mean(res[~val_mask] ** 2)), res,
                                   fit_n, wh, max_ae, bool(acc), rep.stop_reason, rep.epochs,
                                   s_paths, val_mask))
        return members

    # ----------------------------------------------------------------------------- fit
    def fit(self, y, *, usable=None) -> NARForecaster:
        """Fit to the in-sample series ``y`` (daily grid, NaN = missing day).

        Parameters
        ----------
        usable : (n,) bool, optional
            Days that are observed and not imputed (CV samples; spec §2.2 item 4).
            Imputed days may serve as lags and training targets.
        """
        comb, split = self._settings()
        y = np.asarray(y, dtype=float).ravel()
        fin = np.isfinite(y)
        if y.size < 3 or fin.sum() < 3:
            raise InputError(f"need at least 3 values to fit a NAR model, got {int(fin.sum())} "
                             "in-sample")
        if not fin[-1]:
            raise InputError("the last in-sample value (the forecast origin) is missing")
        ok = fin if usable is None else (np.asarray(usable, dtype=bool) & fin)
        self.seed_seq_ = _seed_sequence(self.rng)
        vals = y[fin]
        lo, hi = float(vals.min()), float(vals.max())
        span = hi - lo
        self.constant_ = bool(span < 1e-12 * max(1.0, abs(hi)))
        self.lo_, self.span_ = lo, (0.0 if self.constant_ else span)
        self.y_ = y
        self.combine_, self.split_ = comb, split
        if self.constant_:
            warnings.warn("constant series: the NAR model degrades to persistence",
                          DataQualityWarning, stacklevel=2)
            self.order_ = 1
            self.order_selection_ = None
            self.hidden_, self.hidden_scores_ = int(self.hidden), None
            self.members_, self.chosen_, self.accepted_ = [], [], False
            self.sample_index_ = np.flatnonzero(fin[1:] & fin[:-1]) + 1
            self.fitted_ = y[self.sample_index_ - 1]
            self.whiteness_ = None
            return self
        if self.order is None:
            self.order_selection_: OrderSelection | None = select_order_cv(
                y, H=self._lag_bound(int(ok.sum())), c=self.c, bandwidth=self.bandwidth,
                usable=ok)
            p = self.order_selection_.order
        else:
            # a lag order above half the usable samples leaves nothing to train on
            p = bounded_int("order", self.order, 1, min(MAX_ORDER, max(1, int(ok.sum()) // 2)))
            self.order_selection_ = None
        z = self._to_unit(np.where(fin, y, 0.0))
        idx = np.arange(p, y.size)
        keep = fin[idx].copy()
        for k in range(1, p + 1):
            keep &= fin[idx - k]
        idx = idx[keep]
        if idx.size < 4:
            raise InputError(f"too few complete open-loop samples ({idx.size}) for order {p}")
        U = np.column_stack([z[idx - k] for k in range(1, p + 1)])
        tgt = z[idx]
        lm = dict(self.lm or {})
        R = int(self.restarts)
        if R < 1:
            raise InputError(f"restarts must be >= 1, got {self.restarts}")
        streams = [child.spawn(2) for child in self.seed_seq_.spawn(R)]  # (train, paths)
        sizes = self._hidden_sizes()
        scores: dict = {}
        members = None
        for S in sizes:
            cand = self._train_members(U, tgt, S, streams, split, lm)
            scores[S] = float(np.mean([m.val_mse for m in cand]))
            if members is None or scores[S] < scores[self.hidden_]:
                members, self.hidden_ = cand, S
        self.hidden_scores_ = scores if self.hidden_grid is not None else None
        # spec §3.7: members ranked by validation MSE; "best" takes the best acceptable
        # member (else the best overall), "median"/"mean" the ceil(R/2) best members.
        order = sorted(range(R), key=lambda i: members[i].val_mse)
        if comb == "best":
            acc = [i for i in order if members[i].accepted]
            chosen = (acc or order)[:1]
        else:
            chosen = order[: int(math.ceil(R / 2))]
        self.members_ = members
        self.chosen_ = chosen
        self.accepted_ = all(members[i].accepted for i in chosen)
        self.order_ = p
        self.sample_index_ = idx
        self.U_ = U
        fits = np.array([members[i].fitted for i in chosen])
        comb_fit = fits[0] if comb == "best" else (np.median(fits, axis=0) if comb == "median"
                                                   else np.mean(fits, axis=0))
        self.fitted_ = self._from_unit(comb_fit)
        self.whiteness_ = whiteness(y[idx] - self.fitted_)
        return self

    # ----------------------------------------------------------------------- forecasts
    def _check_fitted(self):
        if not hasattr(self, "order_"):
            raise NotFittedError("NARForecaster.forecast called before fit")

    def _tail(self):
        p = self.order_
        tail = self.y_[-p:]
        if not np.all(np.isfinite(tail)):
            raise InputError(f"the last {p} in-sample values must be present to forecast")
        return self._to_unit(tail)

    def member_forecasts(self, h: int) -> np.ndarray:
        """Deterministic closed-loop forecasts of the retained members, (M, h), original units."""
        self._check_fitted()
        h = int(h)
        if self.constant_:
            return np.full((1, h), self.y_[-1])
        p, S = self.order_, int(self.hidden_)
        tail = self._tail()
        thetas = np.array([self.members_[i].theta for i in self.chosen_])
        M = thetas.shape[0]
        state = np.tile(tail[::-1], (M, 1))  # (M, p): y_{T}, y_{T-1}, ...
        out = np.empty((M, h))
        extrap = False
        for k in range(h):
            v = np.array([forward(thetas[m], state[m:m + 1], S)[0] for m in range(M)])
            out[:, k] = v
            extrap |= bool(np.any(np.abs(v) > 1.5))
            state = np.column_stack([v, state[:, : p - 1]])
        if extrap:
            warnings.warn("closed-loop forecast left [-1.5, 1.5] in normalised units "
                          "(extrapolation beyond the training range)", ExtrapolationWarning,
                          stacklevel=2)
        return self._from_unit(out)

    def forecast_paths(self, h: int, n_paths: int | None = None) -> np.ndarray:
        """Bootstrap closed-loop paths (§3.10), (M * B, h), original units.

        Each retained member simulates B paths adding, at every step, one of its
        centred normalised open-loop residuals drawn with replacement before feeding
        the value back. Seeds come from the member's path stream, so repeated calls
        give the same paths.
        """
        self._check_fitted()
        h = int(h)
        B = int(self.n_paths if n_paths is None else n_paths)
        if self.constant_:
            return np.full((1, h), self.y_[-1])
        p, S = self.order_, int(self.hidden_)
        tail = self._tail()
        paths = []
        for i in self.chosen_:
            mem = self.members_[i]
            gen = np.random.Generator(np.random.PCG64(mem.path_seed))
            r = mem.resid - mem.resid.mean()
            draws = r[gen.integers(0, r.size, size=(B, h))]
            state = np.tile(tail[::-1], (B, 1))
            out = np.empty((B, h))
            for k in range(h):
                v = forward(mem.theta, state, S) + draws[:, k]
                out[:, k] = v
                state = np.column_stack([v, state[:, : p - 1]])
            paths.append(out)
        return self._from_unit(np.vstack(paths))

    def forecast(self, h: int, *, intervals: bool = True) -> Forecast:
        """Closed-loop forecast of steps 1..h with 95 % bootstrap intervals (§3.8, §3.10)."""
        self._check_fitted()
        if int(h) != h or h < 1:
            raise InputError(f"horizon must be a positive integer, got {h}")
        mf = self.member_forecasts(h)
        if self.combine_ == "best" or self.constant_:
            central = mf[0]
        elif self.combine_ == "median":
            central = np.median(mf, axis=0)
        else:
            central = np.mean(mf, axis=0)
        if not intervals:
            return Forecast(central)
        paths = self.forecast_paths(h)
        lo, med, hi = np.quantile(paths, [0.025, 0.5, 0.975], axis=0)
        return Forecast(central, lo, hi, med)

    # -------------------------------------------------------------------------- report
    def one_step(self, lags) -> np.ndarray:
        """Open-loop one-step predictions for rows (y_{t-1}, .., y_{t-p}) in original units,
        combined over the retained members like the forecast."""
        self._check_fitted()
        lags = np.atleast_2d(np.asarray(lags, dtype=float))
        if self.constant_:
            return lags[:, 0].copy()
        Z = self._to_unit(lags)
        preds = np.array([forward(self.members_[i].theta, Z, int(self.hidden_))
                          for i in self.chosen_])
        if self.combine_ == "best":
            c = preds[0]
        elif self.combine_ == "median":
            c = np.median(preds, axis=0)
        else:
            c = np.mean(preds, axis=0)
        return self._from_unit(c)

    def fit_metrics(self) -> dict:
        """In-sample open-loop errors (original units): MSE, RMSE, MaxAE for training,
        validation (of the best retained member's split) and all samples (spec §5)."""
        self._check_fitted()
        y, f = self.y_[self.sample_index_], np.asarray(self.fitted_, dtype=float)
        out = {"all": _err(y, f)}
        if self.members_:
            vm = self.members_[self.chosen_[0]].val_mask
            out["train"] = _err(y[~vm], f[~vm])
            out["validation"] = _err(y[vm], f[vm]) if vm.any() else None
        return out

    def fit_report(self) -> dict:
        """Order, per-member training records and the combination (JSON-ready)."""
        self._check_fitted()
        return {
            "order": self.order_,
            "order_selection": None if self.order_selection_ is None
            else self.order_selection_.to_dict(),
            "combine": self.combine_, "split": self.split_, "constant": self.constant_,
            "chosen": list(self.chosen_), "accepted": self.accepted_,
            "members": [{"val_mse": m.val_mse, "train_mse": m.train_mse,
                         "stop_reason": m.stop_reason, "epochs": m.epochs,
                         "max_ae": m.max_ae, "accepted": m.accepted,
                         "whiteness_passed": m.whiteness.passed,
                         "ljung_box_p": m.whiteness.ljung_box_p} for m in self.members_],
            "fit": self.fit_metrics(),
            "whiteness": None if self.whiteness_ is None else self.whiteness_.to_dict(),
        }

    def residual_check(self) -> Whiteness | None:
        """Whiteness of the combined one-step residuals (§3.9)."""
        self._check_fitted()
        return self.whiteness_

    # ---------------------------------------------------------------------- model file
    def to_dict(self) -> dict:
        """JSON-ready model: settings, scaling, in-sample tail and retained members."""
        self._check_fitted()
        ss = self.seed_seq_
        return {
            "settings": {"order": self.order, "H": self.H, "c": self.c,
                         "bandwidth": self.bandwidth, "hidden": int(self.hidden),
                         "restarts": int(self.restarts), "preset": self.preset,
                         "combine": self.combine, "split": self.split,
                         "val_fraction": float(self.val_fraction), "n_paths": int(self.n_paths),
                         "tol_fit": self.tol_fit,
                         "hidden_grid": None if self.hidden_grid is None
                         else [int(v) for v in self.hidden_grid]},
            "hidden_used": int(self.hidden_),
            "order": int(self.order_), "lo": self.lo_, "span": self.span_,
            "constant": self.constant_, "combine_used": self.combine_,
            "split_used": self.split_, "accepted": bool(self.accepted_),
            "tail": [float(v) for v in self.y_[-self.order_:]],
            "seed_entropy": int(ss.entropy) if ss.entropy is not None else None,
            "members": [{"theta": self.members_[i].theta.tolist(),
                         "resid": self.members_[i].resid.tolist(),
                         "val_mse": self.members_[i].val_mse,
                         "path_seed": {"entropy": int(self.members_[i].path_seed.entropy),
                                       "spawn_key": list(self.members_[i].path_seed.spawn_key)}}
                        for i in self.chosen_],
        }

    @classmethod
    def from_dict(cls, d: dict) -> NARForecaster:
        """Rebuild a fitted forecaster (forecasting only; no training data)."""
        check_own_payload(cls.MODEL_TYPE, d)  # types, shapes, ranges: one line naming the key
        try:
            s = d["settings"]
            obj = cls(**s)
            obj.order_ = int(d["order"])
            obj.hidden_ = int(d.get("hidden_used", obj.hidden))  # format 1 files: no grid
            obj.hidden_scores_ = None
            obj.lo_, obj.span_ = float(d["lo"]), float(d["span"])
            obj.constant_ = bool(d["constant"])
            obj.combine_, obj.split_ = d["combine_used"], d["split_used"]
            obj.accepted_ = bool(d["accepted"])
            bounded_int("order", obj.order_, 1, MAX_ORDER)
            bounded_int("hidden", obj.hidden_, 1, 10_000)
            obj.y_ = np.asarray(d["tail"], dtype=float)
            ent = d.get("seed_entropy")  # kept so that a loaded model saves again
            obj.seed_seq_ = np.random.SeedSequence(None if ent is None else int(ent))
            if obj.y_.shape != (obj.order_,):
                # the forecast's state is the last `order` values, exactly
                raise InputError(f"nar model: the state ('tail') holds {obj.y_.size} values; "
                                 f"a model of order {obj.order_} needs exactly {obj.order_}")
            finite("tail", obj.y_)
            finite("lo", obj.lo_)
            finite("span", obj.span_)
            obj.order_selection_ = None
            obj.whiteness_ = None
            members = []
            for m in d["members"]:
                theta = np.asarray(m["theta"], dtype=float)
                if theta.size != n_params(obj.order_, obj.hidden_):
                    raise InputError("nar model: weight count does not match the architecture")
                finite("theta", theta)
                ps = np.random.SeedSequence(int(m["path_seed"]["entropy"]),
                                            spawn_key=tuple(m["path_seed"]["spawn_key"]))
                resid = np.asarray(m["resid"], dtype=float)
                members.append(_Member(theta, float(m["val_mse"]), float("nan"), resid,
                                       np.zeros(0), None, float("nan"), obj.accepted_, "", 0,
                                       ps, np.zeros(0, bool)))
            obj.members_ = members
            obj.chosen_ = list(range(len(members)))
        except (KeyError, TypeError, ValueError) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(f"nar model: bad payload ({exc})") from None
        return obj


def _err(actual, fitted) -> dict:
    """MSE, RMSE and MaxAE (= ME of the glossary) of ``fitted - actual`` (metrics.py)."""
    if np.size(actual) == 0:
        return {"mse": None, "rmse": None, "max_ae": None, "n": 0}
    return {"mse": metrics.mse(actual, fitted), "rmse": metrics.rmse(actual, fitted),
            "max_ae": metrics.max_abs_error(actual, fitted), "n": int(np.size(actual))}

