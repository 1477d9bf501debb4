"""C99 export of a fuzzy thermal-compensation model (spec 000 §8.4; docs/thermal.md).

:func:`export_c` turns a :class:`~inertialab.calib.thermal.ThermalModel` whose map is
a TSK fuzzy system (FIS, ANFIS, SCM-ANFIS, IAFSA-SCM-ANFIS; the rules read through
:meth:`inertialab.learn.anfis.ANFIS.rules`) into one dependency-free
``.h``/``.c`` pair for a navigation computer: double precision, no allocation, only
``exp`` from libm, constants written with ``%.17g`` so they round-trip exactly. The C
code repeats the Python computation step by step (deployment ``a_i`` estimate, eq. 5,
clamping to the calibrated range with the status codes below, [0, 1] scaling, the
normalised firing strengths with the max-log shift, the consequents), so both agree to
rounding. :func:`export_c` returns the text, :func:`write_c` writes the two files.

Entry points (``PREFIX`` defaults to ``qfa``)::

    double PREFIX_comp_mV(double T_C, double U_mV, double a_p_g, int *status);
    double PREFIX_comp_g(double T_C, double U_mV, double a_p_g, int *status);

``status`` (may be NULL) receives 0 ok, 1 temperature clamped, 2 output clamped, 3 both.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from inertialab.errors import InputError

if TYPE_CHECKING:
    from inertialab.calib.thermal import ThermalModel
    from inertialab.learn.anfis import ScaledRules

__all__ = ["CExport", "MAX_RULES", "export_c", "write_c"]


@dataclass(frozen=True)
class CExport:
    """The generated files and their cost: ``header``/``source`` text, file names,
    ``n_rules``, ``exp_calls`` and ``flops`` per call (approximate, spec 000 §8.4)."""

    header: str
    source: str
    header_name: str
    source_name: str
    n_rules: int
    exp_calls: int
    flops: int
    unit_id: str = ""


#: Characters allowed in data-derived text placed in a C comment; every other one becomes
#: "_" (no "*/", no backslash, no "?" (trigraphs), no newline, ASCII only).
_COMMENT_UNSAFE = re.compile(r"[^A-Za-z0-9 _.,:;+=@%()-]")
#: Rule count above which the export is refused (the stack array lw[NR]; R_max is 40).
MAX_RULES = 1000


def _comment(text, limit: int = 64) -> str:
    """Data-derived text (unit id, method) made safe for a C comment: allow-listed
    characters only, at most ``limit`` of them)."""
    return _COMMENT_UNSAFE.sub("_", str(text))[:limit]


def _f(x: float) -> str:
    return f"{float(x):.17g}"


def _check_constants(named: dict) -> None:
    """Refuse a model whose constants would not compile to a working function: non-finite
    values (C has no literal for them), zero scale factors or spans, non-positive widths,
    empty ranges."""
    for name, v in named.items():
        a = np.asarray(v, dtype=float)
        if not np.all(np.isfinite(a)):
            raise InputError(f"C export: model constant {name} is not finite "
                             f"({a.ravel()[~np.isfinite(a.ravel())][0]}); refusing to generate "
                             "code from it")
    for name in ("K1C", "K1B"):
        if named[name] == 0.0:
            raise InputError(f"C export: model constant {name} (scale factor) is zero")
    for name in ("X_SPAN", "S_T", "S_N"):
        if np.any(np.asarray(named[name]) <= 0):
            raise InputError(f"C export: model constant {name} must be positive")
    if not (named["T_LO"] < named["T_HI"] and named["N_LO"] < named["N_HI"]):
        raise InputError("C export: the model's calibrated range is empty")


def _arr(name: str, values) -> str:
    vals = ", ".join(_f(v) for v in np.asarray(values, float).ravel())
    return f"static const double {name}[] = {{{vals}}};"


def export_c(model: ThermalModel, *, prefix: str = "qfa", unit_ref=None, unit_id: str = "") -> CExport:
    """C99 source for ``model`` (a fuzzy :class:`ThermalModel`).

    Parameters
    ----------
    prefix : C identifier prefix of the two functions and the header (default ``qfa``)
    unit_ref : :class:`~inertialab.sensors.pendulous.SingleAxisCoefficients`, optional
        55 °C coefficients of the unit the code will run on, when it is not the model's
        own unit: the generated code then applies the transfer mapping of spec 000 §3.7
        (Ua from this unit's coefficients, ``N_A = K0c_A + K1c_A (Ua_B - K0c_B)/K1c_B``),
        exactly as :func:`inertialab.calib.thermal.compensate` with ``unit_ref``.
    unit_id : that unit's serial, for the header comment
    """
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]{0,30}", prefix):
        raise InputError(f"C prefix must be a C identifier, got {prefix!r}")
    from inertialab.learn.anfis import ANFIS  # imported on use: the registry stays light

    reg = getattr(model, "regressor", None)
    if not isinstance(reg, ANFIS):
        raise InputError(
            f"C export supports the fuzzy models (fis, anfis, scm-anfis, iafsa-scm-anfis), "
            f"not {getattr(model, 'method', type(model).__name__)!r}")
    rules = reg.rules()
    R = rules.n_rules
    n_in = rules.n_inputs
    if n_in != 2:
        raise InputError("C export expects a two-input (T, N) model")
    c = rules.centers  # (R, 2)
    s = rules.sigmas
    q = rules.consequents  # (R, 3)
    if not 1 <= R <= MAX_RULES:
        raise InputError(f"C export: {R} rules (supported: 1 to {MAX_RULES})")
    ref = model.ref
    ref_b = ref if unit_ref is None else unit_ref
    map_unit = unit_ref is not None
    _check_constants({
        "K0C": ref.k0, "K1C": ref.k1, "K2C": ref.k2, "KIPC": ref.kip, "KPC": ref.kp,
        "K0B": ref_b.k0, "K1B": ref_b.k1, "K2B": ref_b.k2, "KIPB": ref_b.kip, "KPB": ref_b.kp,
        "T_LO": model.t_range_c[0], "T_HI": model.t_range_c[1],
        "N_LO": model.n_range_mv[0], "N_HI": model.n_range_mv[1],
        "X_LO": rules.x_lo, "X_SPAN": rules.x_span, "Y_LO": rules.y_lo, "Y_SPAN": rules.y_span,
        "C_T": c[:, 0], "C_N": c[:, 1], "S_T": s[:, 0], "S_N": s[:, 1],
        "P_T": q[:, 0], "P_N": q[:, 1], "R0": q[:, 2]})
    header = _header(model, prefix, R, map_unit, unit_id)
    source = _source(model, prefix, rules, ref, ref_b, map_unit)
    P = prefix
    return CExport(header=header, source=source, header_name=f"{P}_comp.h",
                   source_name=f"{P}_comp.c", n_rules=R, exp_calls=R, flops=14 * R + 30,
                   unit_id=str(unit_id) if map_unit else "")


def _header(model, P: str, R: int, map_unit: bool, unit_id) -> str:
    """The ``.h`` text of :func:`export_c`."""
    method_txt, unit_txt, b_txt = _comment(model.method), _comment(model.unit_id), _comment(unit_id)
    guard = f"{P.upper()}_COMP_H"
    header = f"""/* {P}_comp.h - temperature compensation of a quartz accelerometer.
 * Generated by inertialab (spec 000 s8.4), model '{method_txt}', unit '{unit_txt}'.
 * Inputs: T_C (internal sensor, deg C), U_mV (raw output, mV), a_p_g (pendulous-axis
 * specific force, g, from the IMU's other axes; ignored by raw-input models).
 * status (may be NULL): 0 ok, 1 temperature clamped, 2 output clamped, 3 both.
 * Calibrated range: T {_f(model.t_range_c[0])} .. {_f(model.t_range_c[1])} deg C.
 * Runs on: {"unit '" + b_txt + "' through its own 55 deg C coefficients (transfer, "
             "spec 000 s3.7)" if map_unit else "the model's own unit"}. */
#ifndef {guard}
#define {guard}

#define {P.upper()}_N_RULES {R}
#define {P.upper()}_STATUS_OK 0
#define {P.upper()}_STATUS_T_CLAMPED 1
#define {P.upper()}_STATUS_N_CLAMPED 2

/* output at the 55 deg C reference, mV */
double {P}_comp_mV(double T_C, double U_mV, double a_p_g, int *status);
/* compensated specific force along the input axis, g */
double {P}_comp_g(double T_C, double U_mV, double a_p_g, int *status);

#endif
"""
    return header


def _source(model, P: str, rules: ScaledRules, ref, ref_b, map_unit: bool) -> str:
    """The ``.c`` text of :func:`export_c`: constants, then the two functions."""
    R, c, s, q = rules.n_rules, rules.centers, rules.sigmas, rules.consequents
    raw = 1 if model.input == "raw" else 0
    source = f"""/* {P}_comp.c - generated by inertialab; C99, no allocation, libm exp only. */
#include <math.h>
#include "{P}_comp.h"

#define NR {R}
static const double K0C = {_f(ref.k0)};
static const double K1C = {_f(ref.k1)};
/* model unit's K2c, Kipc, Kpc: {_f(ref.k2)}, {_f(ref.kip)}, {_f(ref.kp)} (the code uses K2B, KIPB, KPB,
   equal to them unless it runs on another unit) */
/* 55 deg C coefficients of the unit this code runs on (= the model's unless mapped) */
static const double K0B = {_f(ref_b.k0)};
static const double K1B = {_f(ref_b.k1)};
static const double K2B = {_f(ref_b.k2)};
static const double KIPB = {_f(ref_b.kip)};
static const double KPB = {_f(ref_b.kp)};
static const int MAP_UNIT = {1 if map_unit else 0};
static const int RAW_INPUT = {raw};
static const int LEARN_DRIFT = {1 if model.learn_drift else 0};
static const double T_LO = {_f(model.t_range_c[0])}, T_HI = {_f(model.t_range_c[1])};
static const double N_LO = {_f(model.n_range_mv[0])}, N_HI = {_f(model.n_range_mv[1])};
static const double X_LO[2] = {{{_f(rules.x_lo[0])}, {_f(rules.x_lo[1])}}};
static const double X_SPAN[2] = {{{_f(rules.x_span[0])}, {_f(rules.x_span[1])}}};
static const double Y_LO = {_f(rules.y_lo)}, Y_SPAN = {_f(rules.y_span)};
{_arr("C_T", c[:, 0])}
{_arr("C_N", c[:, 1])}
{_arr("S_T", s[:, 0])}
{_arr("S_N", s[:, 1])}
{_arr("P_T", q[:, 0])}
{_arr("P_N", q[:, 1])}
{_arr("R0", q[:, 2])}

double {P}_comp_mV(double T_C, double U_mV, double a_p_g, int *status)
{{
    double N, a, a0, xt, xn, lw[NR], mx, sw = 0.0, sf = 0.0, y;
    int st = 0, i;
    if (RAW_INPUT) {{
        N = MAP_UNIT ? K0C + K1C * (U_mV - K0B) / K1B : U_mV;
    }} else {{
        a0 = (U_mV - K0B - KPB * a_p_g) / K1B;
        a = (U_mV - K0B - KPB * a_p_g - K2B * a0 * a0 - KIPB * a0 * a_p_g) / K1B;
        N = U_mV - K2B * a * a - KIPB * a * a_p_g - KPB * a_p_g;
        N = K0C + K1C * (N - K0B) / K1B;
    }}
    if (T_C < T_LO) {{ T_C = T_LO; st |= 1; }} else if (T_C > T_HI) {{ T_C = T_HI; st |= 1; }}
    if (N < N_LO) {{ y = N_LO; st |= 2; }} else if (N > N_HI) {{ y = N_HI; st |= 2; }} else {{ y = N; }}
    N = y;
    xt = (T_C - X_LO[0]) / X_SPAN[0];
    xn = (N - X_LO[1]) / X_SPAN[1];
    mx = -HUGE_VAL;
    for (i = 0; i < NR; ++i) {{
        double zt = (xt - C_T[i]) / S_T[i], zn = (xn - C_N[i]) / S_N[i];
        lw[i] = -0.5 * (zt * zt) + -0.5 * (zn * zn);
        if (lw[i] > mx) mx = lw[i];
    }}
    for (i = 0; i < NR; ++i) {{
        double w = exp(lw[i] - mx);
        sw += w;
        sf += w * (P_T[i] * xt + P_N[i] * xn + R0[i]);
    }}
    y = Y_LO + Y_SPAN * (sf / sw);
    if (LEARN_DRIFT) y += N;
    if (status) *status = st;
    return y;
}}

double {P}_comp_g(double T_C, double U_mV, double a_p_g, int *status)
{{
    return ({P}_comp_mV(T_C, U_mV, a_p_g, status) - K0C) / K1C;
}}
"""
    return source

def write_c(ex: CExport, directory) -> list[str]:
    """Write the ``.h``/``.c`` pair of :func:`export_c` into ``directory`` (atomically,
    each file); returns their paths."""
    from pathlib import Path

    from inertialab.io.writers import atomic_write_text

    d = Path(directory)
    atomic_write_text(d / ex.header_name, ex.header)
    atomic_write_text(d / ex.source_name, ex.source)
    return [str(d / ex.header_name), str(d / ex.source_name)]
