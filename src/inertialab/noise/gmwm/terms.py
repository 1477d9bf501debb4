"""IEEE 952 terms from a GMWM fit's latent processes (the reading rules of
:mod:`inertialab.noise.gmwm.fit`'s module docstring): Q, N, K and R from the quantisation,
white, random-walk and drift processes, B from the Gauss–Markov processes that make the
flat region, K also from a slow Gauss–Markov process (the wander of a significant rise,
:func:`inertialab.noise.gmwm.fit.is_slow_process`), with its correlation time where it alone is K."""

from __future__ import annotations

import math

import numpy as np

from inertialab.noise.gmwm.fit import BI_FACTOR, GmwmFit, b_of, is_slow_process, k_of, rise_start


def gmwm_noise_terms(fit: GmwmFit, conv, rate_hz: float, result=None):
    """IEEE terms (a :class:`~inertialab.noise.terms.fit.NoiseTerms`, method "gmwm") from a
    GMWM fit (module docstring); ``conv`` is the terms module's unit converter.
    Processes absent from the selected model give their term as 0 with flag ``absent``."""
    from inertialab.noise.terms.base import _REPORT, NoiseTerm, NoiseTerms

    tau0 = fit.wv.tau0_s
    t_rise = rise_start(fit.wv)
    by = {}
    for p in fit.processes:
        by.setdefault(p.kind, []).append(p)
    taus = fit.wv.taus_s
    mm = taus / tau0
    contrib = {p.kind: np.zeros(taus.size) for p in fit.processes}
    for p in fit.processes:
        contrib[p.kind] = contrib[p.kind] + p.avar(mm, tau0)
    tot = sum(contrib.values())

    def rng_of(kind):
        if kind not in contrib:
            return (float("nan"), float("nan"))
        share = contrib[kind] / tot
        on = share >= 0.25
        if not on.any():
            on = share >= share.max()
        return (float(taus[on].min()), float(taus[on].max()))

    # (kind, key, amplitude from the parameter value)
    amp = {"Q": ("QN", "q2", lambda v: math.sqrt(v)),
           "N": ("WN", "sigma2", lambda v: math.sqrt(v * tau0)),
           "K": ("RW", "gamma2", lambda v: math.sqrt(v / tau0)),
           "R": ("DR", "omega", lambda v: v / tau0)}
    terms, coeffs, k_gm = {}, [0.0] * 5, None
    for name in ("Q", "N", "B", "K", "R"):
        unit = _REPORT[conv.kind][name]
        k = conv.factor(name)
        extra = ()
        if name == "B":
            kind = "BL" if "BL" in by else "GM"
            a = b_of(fit.processes, tau0, fit.tau_range_s, t_rise)
            lo_hi = fit.b_ci
            coeffs[2] = (a * BI_FACTOR) ** 2
        elif name == "K" and any(is_slow_process(p, fit.tau_range_s, t_rise) for p in fit.processes):
            kind = "GM"
            a = k_of(fit.processes, tau0, fit.tau_range_s, t_rise)
            lo_hi = fit.k_ci
            extra = ("from_gm",)
            k_gm = _k_time(fit.processes, fit.tau_range_s, t_rise)
        else:
            kind, key, f = amp[name]
            if kind in by:
                a = f(by[kind][0].params[key])
                ci = by[kind][0].ci.get(key)
                lo_hi = (f(ci[0]), f(ci[1])) if ci else (float("nan"), float("nan"))
                if name == "K" and all(math.isfinite(v) for v in fit.k_ci):
                    # the bootstrap K, spanning the models within WIC_WINDOW
                    lo_hi = fit.k_ci
            else:
                a, lo_hi = 0.0, (0.0, 0.0)
        present = kind in by
        flags = (() if present else ("absent",)) + extra
        reason = "" if present else f"not in the model selected by the WIC ({fit.name})"
        ub = float("nan")
        upper = {"K": (fit.k_upper, "a random walk"),
                 "R": (fit.r_upper / tau0, "a drift")}.get(name)
        if upper and not present and math.isfinite(upper[0]):
            lo_hi, ub = (0.0, upper[0]), k * upper[0]
            flags += ("upper_bound",)
            reason += (f"; upper bound: the upper bootstrap percentile of {name} in the "
                       f"best model with {upper[1]}")
        val = k * a
        dens = per = None
        if name == "N":
            dens, per = conv.n_extras(val / conv.value("N", 1.0), rate_hz)
        terms[name] = NoiseTerm(value=val, unit=unit, ci=(k * lo_hi[0], k * lo_hi[1]),
                                method="gmwm", tau_range_s=rng_of(kind), flags=flags,
                                density=dens, per_sample_std=per, reason=reason,
                                upper_bound=ub)
    # five-term coefficients (data unit): c_-2 = 3Q^2, c_-1 = N^2, c_0 = (0.6643 B)^2,
    # c_1 = K^2/3, c_2 = R^2/2
    qa = terms["Q"].value / conv.factor("Q")
    na = terms["N"].value / conv.factor("N")
    ka = terms["K"].value / conv.factor("K")
    ra = terms["R"].value / conv.factor("R")
    coeffs = [3 * qa**2, na**2, coeffs[2], ka**2 / 3, ra**2 / 2]
    return NoiseTerms(**terms, kind=conv.kind, unit=conv.unit, method="gmwm",
                      coefficients=tuple(float(c) for c in coeffs),
                      tau_range_s=fit.tau_range_s, rate_hz=float(rate_hz),
                      confidence=float(fit.wv.confidence),
                      statistic="oadev" if result is None else result.statistic,
                      g_local=conv.g, interval=f"bootstrap-wv/{fit.n_boot}",
                      gmwm=fit.to_dict(), k_gm=k_gm)


def _k_time(processes, tau_range_s, t_rise) -> dict | None:
    """``{"t_s": tc}`` where K is one slow Gauss–Markov process alone (no random walk, no
    other slow GM): the random walk it behaves as is held by its correlation time, as the
    five-term fit's ``k_gm``; else None (K a random walk, or a sum of processes that no
    single time describes)."""
    slow = [p for p in processes if is_slow_process(p, tau_range_s, t_rise)]
    if len(slow) != 1 or any(p.kind == "RW" for p in processes):
        return None
    return {"t_s": float(slow[0].params["tc_s"])}
