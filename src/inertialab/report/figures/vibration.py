"""Figures and report section of the ``vibration`` study (spec 001; seed Figs. 1-8).

:func:`figures` turns a :class:`~inertialab.workflows.vibration.VibrationResult` into the
seed's figures (record with phases, CWT scalogram, decomposition levels, bias curve of
RBF vs polynomial vs measured, compensated signal) plus per-phase Allan curves;
:func:`section` wraps them with the tables for the HTML report.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from inertialab.report.section import Figure, Section, Table

TERMS = ("Q", "N", "B", "K", "R")


def _decimate(t, x, n_max=4000):
    """Block min/max envelope for plotting long records (keeps spikes visible)."""
    n = x.size
    if n <= 2 * n_max:
        return t, x
    k = n // n_max
    m = (n // k) * k
    xb = x[:m].reshape(-1, k)
    tb = t[:m].reshape(-1, k)[:, 0]
    return np.repeat(tb, 2), np.column_stack([xb.min(1), xb.max(1)]).ravel()


def _shade(ax, fs, k_on, k_off):
    ax.axvspan(k_on / fs, k_off / fs, color="tab:orange", alpha=0.12, lw=0, label="P2 vibration")


def _fig_record(res):
    v = res.views
    fig, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=False)
    for ax, name in zip(axes, ("sweep", "fixed")):
        d = v.get(name)
        if d is None:
            ax.set_visible(False)
            continue
        fs = d["fs_hz"]
        t = np.arange(d["rate"].size) / fs
        tt, xx = _decimate(t, d["rate"])
        ax.plot(tt, xx, lw=0.4, color="0.5", label="raw rate")
        ta, xa = _decimate(t, d["approx"])
        ax.plot(ta, xa, lw=0.8, color="tab:blue", label=f"A{res.level}")
        _shade(ax, fs, d["k_on"], d["k_off"])
        ax.set_ylabel("rate [deg/h]")
        ax.set_title(f"{name} run: P1 static, P2 vibration, P3 static")
        ax.legend(loc="upper right", fontsize=7)
    axes[-1].set_xlabel("time [s]")
    fig.tight_layout()
    return Figure(fig, "Records of the sweep (E1) and 500-Hz (E2) runs with their phases "
                       "(seed Fig. 1) and the level-L approximation.", "record")


def _fig_scalogram(res):
    sc = res.views.get("scalogram")
    if sc is None:
        return None
    fig, ax = plt.subplots(figsize=(9, 4))
    t = sc.time_s
    pdb = sc.power_db
    im = ax.pcolormesh(np.arange(t.size), sc.freq_hz, pdb, shading="auto", cmap="viridis",
                       vmin=np.percentile(pdb, 5), vmax=np.percentile(pdb, 99.5))
    ax.set_yscale("log")
    step = max(1, t.size // 8)
    ax.set_xticks(np.arange(0, t.size, step))
    t0 = res.views.get("scalogram_t0_s", 0.0)
    ax.set_xticklabels([f"{t0 + t[i]:.0f}" for i in range(0, t.size, step)], fontsize=7)
    ax.set_xlabel("time [s]" + (" (record cropped around the edges)"
                                if res.views.get("scalogram_cropped") else ""))
    ax.set_ylabel("frequency [Hz]")
    fig.colorbar(im, ax=ax, label="|W|^2 [dB re (deg/h)^2]")
    ax.set_title("CWT scalogram (cmor1.5-1.0), fixed-frequency run")
    fig.tight_layout()
    return Figure(fig, "CWT scalogram of the 500-Hz run (seed Fig. 2c): P1 quiet, P2 "
                       "high-frequency energy (the 500-Hz drive aliases to 100 Hz at "
                       "fs = 200 Hz), P3 quiet again.", "scalogram")


def _fig_spectra(res):
    w = res.views.get("welch")
    if not w:
        return None
    fig, ax = plt.subplots(figsize=(9, 3.6))
    for name, sp in w.items():
        ax.loglog(sp.freq_hz[1:], sp.asd[1:], lw=0.8, label=name)
    for a in res.views.get("alias_hz", []):
        if a > 0:
            ax.axvline(a, color="k", ls=":", lw=0.7)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("ASD [(deg/h)/sqrt(Hz)]")
    ax.legend(fontsize=7)
    ax.set_title("Welch amplitude spectrum per phase (dotted: aliases of the drive harmonics)")
    fig.tight_layout()
    return Figure(fig, "FFT (Welch) view per phase (seed Fig. 2a): vibration raises the "
                       "high-frequency noise.", "spectra")


def _fig_emd(res):
    e = res.views.get("emd")
    if e is None or e["imfs"].size == 0:
        return None
    k = min(4, e["imfs"].shape[0])
    fig, axes = plt.subplots(k + 1, 1, figsize=(9, 1.3 * (k + 1)), sharex=True)
    axes[0].plot(e["t_s"], e["x"], lw=0.4, color="0.3")
    axes[0].set_ylabel("x")
    for i in range(k):
        axes[i + 1].plot(e["t_s"], e["imfs"][i], lw=0.4)
        axes[i + 1].set_ylabel(f"IMF{i + 1}")
    axes[-1].set_xlabel("time [s]")
    axes[0].set_title(f"EMD of a window at the vibration onset ({e['backend']} sifting)")
    fig.tight_layout()
    return Figure(fig, "EMD around the vibration onset (seed Fig. 2b): the IMFs mix modes on "
                       "this noisy signal, which is why the seed turns to the CWT.", "emd")


def _fig_levels(res):
    d = res.views.get("decomposition")
    if d is None:
        return None
    dec, fs = d["dec"], d["fs_hz"]
    levels = [2, 4, 6, 8, 10]
    levels = [j for j in levels if j <= dec.level]
    fig, axes = plt.subplots(len(levels), 2, figsize=(10, 1.5 * len(levels)), sharex=True)
    t = np.arange(dec.n) / fs
    for i, j in enumerate(levels):
        for col, (sig, lab) in enumerate(((dec.approximation(j), f"A{j}"),
                                          (dec.detail(j), f"D{j}"))):
            ax = axes[i, col] if len(levels) > 1 else axes[col]
            tt, xx = _decimate(t, sig, 2000)
            ax.plot(tt, xx, lw=0.5)
            _shade(ax, fs, d["k_on"], d["k_off"])
            ax.set_ylabel(lab, fontsize=8)
            ax.tick_params(labelsize=7)
    fig.suptitle(f"db4 decomposition of the {d['run']} run (approximations and details)",
                 fontsize=9)
    fig.tight_layout()
    return Figure(fig, "Mallat db4 decomposition (seed Figs. 3-4): low levels carry drift and "
                       "noise; at high levels P2 keeps the vibration bias.", "levels")


def _fig_bias(res):
    v = res.views
    tg = v.get("targets")
    if tg is None:
        return None
    fig, ax = plt.subplots(figsize=(9, 4))
    ax.plot(tg.f_hz, tg.e_dph, ".", ms=2.5, color="0.4", label="measured (E1 bins)")
    ax.plot(v["curve_f_hz"], v["curve_rbf"], lw=1.0, label=f"RBF ({res.fit['rbf']['neurons']} "
                                                            "neurons)")
    ax.plot(v["curve_f_hz"], v["curve_poly"], lw=1.2, label="4th-order polynomial")
    if v.get("curve_truth") is not None:
        ax.plot(v["curve_f_hz"], v["curve_truth"], "k--", lw=0.8, label="simulated truth b_v(f)")
    ax.set_xlabel("vibration frequency [Hz]")
    ax.set_ylabel("bias error [deg/h]")
    ax.legend(fontsize=8)
    ax.set_title("Bias error versus vibration frequency")
    fig.tight_layout()
    return Figure(fig, "RBF network versus 4th-order polynomial on the bias-vs-frequency "
                       "targets of the sweep (seed Fig. 6).", "bias_curve")


def _fig_compensated(res):
    d = res.views.get("fixed")
    if d is None:
        return None
    fs = d["fs_hz"]
    t = np.arange(d["rate"].size) / fs
    fig, ax = plt.subplots(figsize=(9, 4))
    for key, lab, c in (("approx", f"denoised A{res.level}", "tab:blue"),
                        ("poly", "polynomial-compensated", "tab:green"),
                        ("rbf", "RBF-compensated", "tab:red")):
        tt, xx = _decimate(t, d[key])
        ax.plot(tt, xx, lw=0.6, color=c, label=lab)
    _shade(ax, fs, d["k_on"], d["k_off"])
    ax.set_xlabel("time [s]")
    ax.set_ylabel("rate [deg/h]")
    ax.legend(fontsize=8)
    ax.set_title("Fixed 500-Hz run after denoising and compensation")
    fig.tight_layout()
    return Figure(fig, "Compensation of the 500-Hz run (seed Figs. 7-8): the offset of P2 is "
                       "removed except near the vibration edges.", "compensated")


def figures(res) -> list[Figure]:
    """All figures of a :class:`~inertialab.workflows.vibration.VibrationResult`."""
    out = []
    for fn in (_fig_record, _fig_scalogram, _fig_spectra, _fig_emd, _fig_levels, _fig_bias,
               _fig_compensated):
        f = fn(res)
        if f is not None:
            out.append(f)
    return out


def _table(title, rows: dict, note=""):
    units = next(iter(rows.values())) if rows else {}
    cols = ["row"] + [f"{k} [{units[k]['unit']}]" if units else k for k in TERMS]
    return Table(title=title, columns=cols,
                 rows=[[name] + [r[k]["value"] for k in TERMS] for name, r in rows.items()],
                 note=note)


def tables(res) -> list[Table]:
    """The Table 1-3 analogues, the fit table and the level table."""
    t = res.tables
    out = [
        _table("Table 1 analogue: noise terms per phase (OADEV, WLS)", t["phases"]),
        _table("Table 2 analogue: raw vs A_L vs x - A_L (OADEV, OLS as in the paper)",
               t["decomposition"]),
    ]
    if t["compensation"]:
        out.append(_table("Table 3 analogue: fixed run raw, denoised, RBF- and "
                          "polynomial-compensated (WLS; A_L rows on tau >= 2^(L+1) tau0)",
                          t["compensation"], res.metrics.get("compensation_note", "")))
    f = res.fit
    out.append(Table(title="Bias models (deg/h)",
                     columns=["model", "neurons", "train RMSE", "held-out RMSE",
                              "RMSE vs truth"],
                     rows=[[m, f[m].get("neurons"), f[m]["train_rmse"], f[m]["heldout_rmse"],
                            f[m].get("truth_rmse")] for m in ("rbf", "poly")]))
    sel = res.level_selection
    out.append(Table(title=f"Level rule delta_j (threshold {sel.threshold}); chosen "
                           f"L* = {sel.level}, used L = {res.level}",
                     columns=["j", "delta_j", "D_j power P1", "D_j power P2"],
                     rows=[[j, d, sel.detail_power_reference.get(j),
                            sel.detail_power_window.get(j)] for j, d in sel.delta.items()]))
    if "residual" in res.metrics:
        r = res.metrics["residual"]
        out.append(Table(title="Residual bias and edge metrics of the fixed run (deg/h)",
                         columns=["signal", "Delta_b", "edge on", "edge off",
                                  "10-s stability P2"],
                         rows=[[k, v["delta_b"], v["edge_on"], v["edge_off"],
                                v["stability_10s"].get("P2")] for k, v in r.items()]))
    return out


def section(result) -> Section:
    """Report section of the ``vibration`` study (a :class:`StudyResult`)."""
    res = result.data["result"]
    return Section(key="vibration", title=result.title, paragraphs=list(result.text),
                   tables=tables(res), figures=figures(res), results=dict(result.tables),
                   settings=dict(result.settings))
