"""Regenerate the PHASE.DAT-style clock record and its reference tables.

Run from the repository root (needs allantools; not part of the test run)::

    python tests/data/make_clock_reference.py

Writes ``tests/data/clock_phase_ref.dat`` (the record) and
``tests/data/clock_phase_ref_tables.csv`` (deviation, alpha, EDF and 68.3 % interval per
statistic and tau). Nothing here imports inertialab: every number comes from allantools
(deviations, noise identification, Greenhall / Table 7 / Table 8 EDFs and its
``confidence_interval``) or, where allantools has no EDF (HTOTDEV, Theo1), from the
published formulas of NIST SP 1065 §5.2.14-5.2.15 written out below. Provenance and the
recipe: tests/data/README.md.
"""

from __future__ import annotations

import contextlib
import io
import math
from pathlib import Path

import allantools as at
import numpy as np

HERE = Path(__file__).resolve().parent
N_PHASE = 1001
TAU0 = 1.0
SEED = 20260115
CI = 0.683


def make_record() -> np.ndarray:
    """Phase (s) of a simulated oscillator, 1001 points at tau0 = 1 s: white FM (1e-11
    per sample), random-walk FM (4e-13 per sample) and white PM (3e-11 s)."""
    rng = np.random.default_rng(SEED)
    n = N_PHASE - 1
    y = 1e-11 * rng.standard_normal(n) + np.cumsum(4e-13 * rng.standard_normal(n))
    x = np.concatenate(([0.0], np.cumsum(y) * TAU0))
    return x + 3e-11 * rng.standard_normal(N_PHASE)


def sp1065_table5_edf(n, m, alpha):
    """NIST SP 1065 Table 5, the simple overlapping-Allan EDF (N phase points; FFM at
    m = 1 with (N-2) squared as SP 1065 prints it; allantools' edf_simple drops the
    square)."""
    if alpha >= 2:
        return (n + 1) * (n - 2 * m) / (2 * (n - m))
    if alpha == 1:
        return math.exp(math.sqrt(math.log((n - 1) / (2 * m))
                                  * math.log((2 * m + 1) * (n - 1) / 4)))
    if alpha == 0:
        return (3 * (n - 1) / (2 * m) - 2 * (n - 2) / n) * 4 * m**2 / (4 * m**2 + 5)
    if alpha == -1:
        return 2 * (n - 2) ** 2 / (2.3 * n - 4.9) if m == 1 else 5 * n**2 / (4 * m * (n + 3 * m))
    return (n - 2) / (m * (n - 3) ** 2) * ((n - 1) ** 2 - 3 * m * (n - 1) + 4 * m**2)


def htot_edf(n, m, alpha):
    """SP 1065 §5.2.14 / Howe et al. (PTTI 2000): (N/m)/(b0 + b1 m/N) for m >= 16 and FM
    noise alpha 0, -1, -2; otherwise SP 1065 Table 5 (the rule Stable32's printed HTOTDEV
    bounds follow, docs/allan.md), Greenhall's overlapping-Hadamard EDF for alpha < -2."""
    table = {0: (0.559, 1.004), -1: (0.868, 1.140), -2: (0.938, 1.696)}
    if m >= 16 and alpha in table:
        b0, b1 = table[alpha]
        return (n / m) / (b0 + b1 * m / n)
    if alpha >= -2:
        return sp1065_table5_edf(n, m, alpha)
    return at.edf_greenhall(alpha=max(alpha, -4), d=3, m=m, N=n, overlapping=True,
                            modified=False)


def theo1_edf(n, m, alpha):
    """SP 1065 §5.2.15 / Howe & Peppler (2003), r = 0.75 m."""
    r = 0.75 * m
    if alpha >= 2:
        return 0.86 * (n + 1) * (n - 4 * r / 3) / (n - r) * (r / (r + 1.14))
    if alpha == 1:
        return (4.798 * n**2 - 6.374 * n * r + 12.387 * r) / (math.sqrt(r + 36.6) * (n - r)) \
            * (r / (r + 0.3))
    if alpha == 0:
        return ((4.1 * n + 0.8) / r - (3.1 * n + 6.5) / n) * (r**1.5 / (r**1.5 + 5.2))
    if alpha == -1:
        return (2 * n**2 - 1.3 * n * r - 3.5 * r) / (n * r) * (r**3 / (r**3 + 2.3))
    return (4.4 * n - 2) / (2.9 * r) * (((4.4 * n - 1) ** 2 - 8.6 * r * (4.4 * n - 1)
                                        + 11.4 * r**2) / (4.4 * n - 3) ** 2)


GREENHALL = {"adev": (2, False, False), "oadev": (2, True, False), "mdev": (2, True, True),
             "tdev": (2, True, True), "hdev": (3, False, False), "ohdev": (3, True, False)}
MAX_M = {"adev": lambda n: (n - 1) // 2, "oadev": lambda n: (n - 1) // 2,
         "mdev": lambda n: (n - 1) // 3, "tdev": lambda n: (n - 1) // 3,
         "hdev": lambda n: (n - 1) // 3, "ohdev": lambda n: (n - 1) // 3,
         "totdev": lambda n: n - 2, "mtotdev": lambda n: n // 3, "ttotdev": lambda n: n // 3,
         "htotdev": lambda n: (n - 1) // 3, "theo1": lambda n: n - 2,
         "mtie": lambda n: n - 1, "tierms": lambda n: n - 1}


def alpha_of(x, m, dmax, last):
    """allantools' lag-1 ACF noise identification at m (the previous alpha where it
    cannot identify: too few points)."""
    try:
        return int(at.autocorr_noise_id(x, int(m), data_type="phase", dmin=0, dmax=dmax)[0])
    except Exception:  # allantools raises plain errors when the data run out
        return last


def edf_of(stat, n, m, alpha):
    if stat in GREENHALL:
        d, over, mod = GREENHALL[stat]
        lo = -4 if d == 3 else -2
        return at.edf_greenhall(alpha=max(min(alpha, 2), lo), d=d, m=int(m), N=n,
                                overlapping=over, modified=mod)
    if stat == "totdev":
        if alpha > 0:  # Table 7 has FM rows only; PM noise: SP 1065 Table 5 (§5.2.11)
            return sp1065_table5_edf(n, int(m), min(alpha, 2))
        return at.edf_totdev(n, m, max(alpha, -2))
    if stat in ("mtotdev", "ttotdev"):
        if m < 16:  # Stable32 (and SigmaTau): the MDEV EDF below m = 16
            return at.edf_greenhall(alpha=max(min(alpha, 2), -2), d=2, m=int(m), N=n,
                                    overlapping=True, modified=True)
        with contextlib.redirect_stdout(io.StringIO()):  # edf_mtotdev prints its b, c
            return at.edf_mtotdev(n, m, max(min(alpha, 2), -2))
    if stat == "htotdev":
        return htot_edf(n, int(m), alpha)
    if stat == "theo1":
        return theo1_edf(n, m, max(min(alpha, 2), -2))
    return float("nan")


def tables(x) -> list[str]:
    n = x.size
    rows = ["statistic,m,tau_s,dev,alpha,edf,ci_low,ci_high"]
    for stat in ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "totdev", "mtotdev",
                 "ttotdev", "htotdev", "theo1", "mtie", "tierms"):
        top = MAX_M[stat](n)
        ms = [2**k for k in range(int(math.log2(top)) + 1)]
        if stat == "theo1":
            ms = [m for m in ms if m >= 2]
        func = getattr(at, stat)
        _, devs, _, _ = func(x, rate=1.0 / TAU0, data_type="phase",
                             taus=np.array(ms, dtype=float) * TAU0)
        dmax = 3 if stat in ("hdev", "ohdev", "htotdev") else 2
        last = 0
        for m, dev in zip(ms, devs):
            m_id = max(1, round(0.75 * m)) if stat == "theo1" else m
            alpha = alpha_of(x, m_id, dmax, last) if stat not in ("mtie", "tierms") else 0
            last = alpha
            edf = edf_of(stat, n, m, alpha)
            if np.isfinite(edf) and edf > 0:
                lo, hi = at.confidence_interval(dev, edf, ci=CI)
            else:
                lo = hi = float("nan")
            tau = 0.75 * m * TAU0 if stat == "theo1" else m * TAU0
            rows.append(f"{stat},{m},{tau!r},{float(dev)!r},{alpha},{float(edf)!r},"
                        f"{float(lo)!r},{float(hi)!r}")
    return rows


def main() -> None:
    x = make_record()
    head = ("# PHASE.DAT-style clock phase record, seconds, tau0 = 1 s, 1001 points;\n"
            "# generated by tests/data/make_clock_reference.py (provenance: README.md)\n")
    (HERE / "clock_phase_ref.dat").write_text(head + "".join(f"{v:.17e}\n" for v in x))
    x = np.loadtxt(HERE / "clock_phase_ref.dat")  # tables from the stored digits
    with contextlib.redirect_stdout(io.StringIO()):
        rows = tables(x)
    (HERE / "clock_phase_ref_tables.csv").write_text(
        f"# reference tables of clock_phase_ref.dat (allantools {at.__version__} + SP 1065 "
        "EDFs), confidence 0.683; provenance: README.md\n" + "\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
