"""A start-of-log transient (warm-up), found against the rest of the log.

IEEE Std 952-1997 (Annex C test procedures) starts the static record once the sensor
has reached thermal equilibrium: the first minutes of a log often carry the bias
settling exponentially while the die warms. Such a transient is neither white noise
nor a random walk; left in, it raises the long-tau Allan variance and biases the drift a
model predicts for the rest of the log.

:func:`detect_warmup` judges a series (one IMU axis, or a temperature column) by its
block means (blocks of ``block_s`` seconds, NaN samples left out). For each window ``L``
of an octave grid (two blocks up to an eighth of the log) it takes the difference ``D(L)``
between the mean of the first window and the mean of the next one. For a stationary
series ``D(L)`` has variance ``2 sigma_A^2(L)``, whatever the noise (white, flicker,
Gauss-Markov, random walk, a ramp): that is the Allan variance's own definition. So the
start is judged against the rest of the log: ``sigma_A(L)`` is the overlapping Allan
deviation of the block means from ``REST_FROM`` (a quarter) of the log to its end, and
``z = D / (sqrt 2 sigma_A)`` is read as Student's t with the rest's count of
non-overlapping window pairs as degrees of freedom. The p value is the least over the
windows times their count (Bonferroni). A transient is reported when ``p < alpha``
(default 0.01); it goes on, block by block, while the same test started there is
significant at ``ALPHA_END`` (0.05), at most half the log: its end is where the
remaining transient can no longer be told from the noise of the rest. Evidence: the
offset ``D`` at the most significant window, that window, ``z``, ``p`` and ``sigma_A``.

On 20 three-hour seeds of three presets (stationary by construction, ramps and random
walks included) nothing is reported at alpha = 0.01; a transient of 10 block standard
deviations is found (tests/noise/test_warmup.py, benchmarks/drift_check.py).

Hand-written; tested on simulated logs with a known exponential warm-up and on
stationary presets (tests/noise/test_warmup.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from inertialab.errors import InputError

#: blocks a log is cut into for the level (their length clipped to BLOCK_S_RANGE)
N_BLOCKS = 512
#: shortest and longest block, s
BLOCK_S_RANGE = (1.0, 60.0)
#: a detected transient goes on while its start is significant at this level
ALPHA_END = 0.05
#: the rest of the log, against which the start is judged, begins at this fraction
REST_FROM = 0.25
#: significance of a reported transient (after the grid's Bonferroni factor)
ALPHA = 0.01


@dataclass(frozen=True)
class Warmup:
    """A start-of-log transient of one series.

    ``detected``; ``warmup_s``: where it ends (0 when not detected), s; ``offset``: the
    first window's mean minus the next window's (the series' unit) at the most
    significant window ``window_s``; ``z`` there and ``p_value`` (Bonferroni over the
    windows); ``block_s``; ``sigma_allan``: the rest's Allan deviation at that window
    (the series' unit)."""

    detected: bool
    warmup_s: float
    offset: float
    window_s: float
    z: float
    p_value: float
    block_s: float
    sigma_allan: float
    extra: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        def num(v):
            return float(v) if math.isfinite(v) else None

        return {"detected": bool(self.detected), "warmup_s": float(self.warmup_s),
                "offset": num(self.offset), "window_s": num(self.window_s),
                "z": num(self.z), "p_value": num(self.p_value),
                "block_s": float(self.block_s), "sigma_allan": num(self.sigma_allan),
                **self.extra}


def block_means(y, rate_hz: float, block_s: float) -> tuple[np.ndarray, np.ndarray]:
    """``(t_mid_s, means)`` of consecutive blocks of ``block_s`` seconds (NaN samples
    left out; a block with none finite is dropped)."""
    y = np.asarray(y, dtype=float)
    nb = max(int(round(block_s * rate_hz)), 1)
    k = y.size // nb
    blocks = y[: k * nb].reshape(k, nb)
    ok = np.isfinite(blocks)
    cnt = ok.sum(axis=1)
    s = np.where(ok, blocks, 0.0).sum(axis=1)
    t = (np.arange(k) + 0.5) * nb / rate_hz
    keep = cnt > 0
    return t[keep], s[keep] / np.maximum(cnt[keep], 1)


def default_block_s(n: int, rate_hz: float) -> float:
    """``N_BLOCKS`` blocks over the log, clipped to ``BLOCK_S_RANGE`` seconds."""
    lo, hi = BLOCK_S_RANGE
    return float(min(max(n / rate_hz / N_BLOCKS, lo), hi))


def _avar_blocks(m, lb: int) -> float:
    """Overlapping Allan variance of a block-mean series at ``lb`` blocks."""
    c = np.concatenate([[0.0], np.cumsum(m)])
    w = (c[lb:] - c[:-lb]) / lb
    d = w[lb:] - w[:-lb]
    return 0.5 * float(np.mean(d * d)) if d.size else math.nan


def _z_at(c, start: int, lbs, sd) -> np.ndarray:
    """``D(L) / (sqrt 2 sigma_A(L))`` at block ``start`` for each window ``L`` (blocks):
    ``D`` the mean of the window from ``start`` minus the next window's."""
    out = np.full(len(lbs), 0.0)
    for i, lb in enumerate(lbs):
        e = start + 2 * lb
        if e < c.size and sd[i] > 0:
            d = (c[start + lb] - c[start]) / lb - (c[e] - c[start + lb]) / lb
            out[i] = d / (math.sqrt(2.0) * sd[i])
    return out


def _none(block_s, p=1.0, why=None) -> Warmup:
    extra = {"reason": why} if why else {}
    return Warmup(False, 0.0, math.nan, math.nan, math.nan, p, block_s, math.nan,
                  extra=extra)


def detect_warmup(y, rate_hz: float, *, block_s: float | None = None,
                  alpha: float = ALPHA) -> Warmup:
    """The warm-up of one series (module docstring): samples ``y`` at ``rate_hz`` Hz."""
    from scipy.special import stdtr

    if not (math.isfinite(rate_hz) and rate_hz > 0):
        raise InputError(f"argument 'rate_hz' must be positive, got {rate_hz}")
    y = np.asarray(y, dtype=float)
    bs = float(block_s) if block_s else default_block_s(y.size, rate_hz)
    t, m = block_means(y, rate_hz, bs)
    if m.size < 32:
        return _none(bs, why=f"too few {bs:g}-s blocks ({m.size}) to judge a transient")
    rest = m[int(REST_FROM * m.size):]
    lbs = [2 ** k for k in range(1, 20) if 2 ** (k + 3) <= m.size]
    sd = np.array([math.sqrt(max(_avar_blocks(rest, lb), 0.0)) for lb in lbs])
    dof = np.array([max(rest.size // lb - 1, 1) for lb in lbs], dtype=float)
    c = np.concatenate([[0.0], np.cumsum(m)])

    def p_at(start):
        z = _z_at(c, start, lbs, sd)
        p = 2.0 * stdtr(dof, -np.abs(z))
        i = int(np.argmin(p))
        return min(1.0, float(p[i]) * len(lbs)), i, z

    p0, i0, z0 = p_at(0)
    if p0 >= alpha:
        return _none(bs, p0)
    end = 0
    while end < m.size // 2 and p_at(end)[0] < ALPHA_END:
        end += 1
    lb = lbs[i0]
    d = z0[i0] * math.sqrt(2.0) * sd[i0]
    return Warmup(True, float(end * bs), float(d), float(lb * bs), float(z0[i0]), p0, bs,
                  float(sd[i0]), extra={"dof": float(dof[i0])})


def log_warmup(series: dict, rate_hz: float, *, setting="auto",
               block_s: float | None = None) -> dict:
    """One warm-up span for a log of several series (``{name: samples}``, the axes and a
    temperature column where there is one): ``setting`` ``"auto"`` (the latest end over
    the series' detected transients), a number of seconds (given), or 0 (none).

    Returns ``{"setting", "span_s", "n_samples", "by": {name: Warmup.to_dict()},
    "from": [names whose end is the span]}``; ``by`` is filled for ``auto`` and for a
    given span alike (the evidence is the same test)."""
    auto = isinstance(setting, str) and setting.strip().lower() == "auto"
    if not auto:
        try:
            given = float(setting)
        except (TypeError, ValueError):
            raise InputError(f"argument 'warmup' must be auto, seconds or 0, got "
                             f"'{setting}'") from None
        if not (math.isfinite(given) and given >= 0):
            raise InputError(f"argument 'warmup' must be auto, seconds or 0, got "
                             f"'{setting}'")
    found = {k: detect_warmup(v, rate_hz, block_s=block_s) for k, v in series.items()}
    if auto:
        span = max([w.warmup_s for w in found.values() if w.detected] + [0.0])
    else:
        span = given
    n_any = min(np.asarray(v).size for v in series.values()) if series else 0
    if span * rate_hz >= 0.5 * n_any and not auto and n_any:
        raise InputError(f"argument 'warmup' {span:g} s leaves less than half of the "
                         f"{n_any / rate_hz:g}-s log")
    src = [k for k, w in found.items() if w.detected and w.warmup_s == span and auto]
    return {"setting": "auto" if auto else float(given), "span_s": float(span),
            "n_samples": int(round(span * rate_hz)),
            "by": {k: w.to_dict() for k, w in found.items()}, "from": src}


__all__ = ["ALPHA", "BLOCK_S_RANGE", "N_BLOCKS", "Warmup", "block_means", "default_block_s",
           "detect_warmup", "log_warmup"]
