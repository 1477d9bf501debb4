"""Figures and report section of the ``vibration`` study (spec 001; Fang et al. Figs. 1-8).

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

from inertialab.report.decimate import plot_m4_even
from inertialab.report.section import Figure, Section, Table

TERMS = ("Q", "N", "B", "K", "R")


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
        plot_m4_even(ax, d["rate"], 1 / fs, lw=0.4, color="0.5", label="raw rate")
        plot_m4_even(ax, d["approx"], 1 / fs, lw=0.8, color="tab:blue", label=f"A{res.level}")
        _shade(ax, fs, d["k_on"], d["k_off"])
        ax.set_ylabel("rate [deg/h]")
        ax.set_title(f"{name} run: P1 static, P2 vibration, P3 static")
        ax.legend(loc="upper right", fontsize=7)
    axes[-1].set_xlabel("time [s]")
    return Figure(fig, "Records of the sweep (E1) and 500-Hz (E2) runs with their phases "
                       "(Fang et al., spec 001, Fig. 1) and the level-L approximation.", "record")


_SUPER = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _log_frequency_image(ax, z, freq, **kw):
    """``z`` (frequency x time) over cell-centred time indices and frequencies ``freq``,
    the frequency axis logarithmic. A geometric ``freq`` grid (the CWT's scales) is drawn
    as one image over log10(f) with decade ticks (the quad mesh of ``pcolormesh`` drew
    96 x 4096 cells one by one: ~0.2 s of the report); any other grid
    as ``pcolormesh`` on a log axis. Returns the mappable for the colour bar."""
    lf = np.log10(freq)
    step = np.diff(lf)
    if lf.size < 2 or not np.allclose(step, step[0], rtol=1e-6, atol=0) or step[0] == 0:
        im = ax.pcolormesh(np.arange(z.shape[1]), freq, z, shading="auto", **kw)
        ax.set_yscale("log")
        return im
    d = abs(step[0])
    top_first = step[0] < 0  # row 0 is the highest frequency
    im = ax.imshow(z if top_first else z[::-1], aspect="auto", interpolation="nearest",
                   origin="upper", extent=(-0.5, z.shape[1] - 0.5, lf.min() - d / 2,
                                           lf.max() + d / 2), **kw)
    lo, hi = lf.min() - d / 2, lf.max() + d / 2
    decades = np.arange(np.ceil(lo), np.floor(hi) + 1)
    minor = [np.log10(k) + e for e in np.arange(np.floor(lo), np.ceil(hi) + 1)
             for k in range(2, 10) if lo <= np.log10(k) + e <= hi]
    ax.set_yticks(decades, ["10" + str(int(e)).translate(_SUPER) for e in decades])
    ax.set_yticks(minor, minor=True)
    return im


def _fig_scalogram(res):
    sc = res.views.get("scalogram")
    if sc is None:
        return None
    fig, ax = plt.subplots(figsize=(9, 4))
    t = sc.time_s
    pdb = sc.power_db
    im = _log_frequency_image(ax, pdb, np.asarray(sc.freq_hz, dtype=float), cmap="viridis",
                              vmin=np.percentile(pdb, 5), vmax=np.percentile(pdb, 99.5))
    step = max(1, t.size // 8)
    ax.set_xticks(np.arange(0, t.size, step))
    t0 = res.views.get("scalogram_t0_s", 0.0)
    ax.set_xticklabels([f"{t0 + t[i]:.0f}" for i in range(0, t.size, step)], fontsize=7)
    ax.set_xlabel("time [s]" + (" (record cropped around the edges)"
                                if res.views.get("scalogram_cropped") else ""))
    ax.set_ylabel("frequency [Hz]")
    fig.colorbar(im, ax=ax, label="|W|^2 [dB re (deg/h)^2]")
    ax.set_title("CWT scalogram (cmor1.5-1.0), fixed-frequency run")
    return Figure(fig, "CWT scalogram of the 500-Hz run (Fang et al., spec 001, Fig. 2c): P1 quiet, P2 "
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
    return Figure(fig, "FFT (Welch) view per phase (Fang et al., spec 001, Fig. 2a): vibration raises the "
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
    return Figure(fig, "EMD around the vibration onset (Fang et al., spec 001, Fig. 2b): the IMFs mix modes on "
                       "this noisy signal, which is why the seed turns to the CWT.", "emd")


def _fig_levels(res):
    d = res.views.get("decomposition")
    if d is None:
        return None
    dec, fs = d["dec"], d["fs_hz"]
    levels = [2, 4, 6, 8, 10]
    levels = [j for j in levels if j <= dec.level]
    fig, axes = plt.subplots(len(levels), 2, figsize=(10, 1.5 * len(levels)), sharex=True)
    for i, j in enumerate(levels):
        for col, (sig, lab) in enumerate(((dec.approximation(j), f"A{j}"),
                                          (dec.detail(j), f"D{j}"))):
            ax = axes[i, col] if len(levels) > 1 else axes[col]
            plot_m4_even(ax, sig, 1 / fs, lw=0.5)
            _shade(ax, fs, d["k_on"], d["k_off"])
            ax.set_ylabel(lab, fontsize=8)
            ax.tick_params(labelsize=7)
    fig.suptitle(f"db4 decomposition of the {d['run']} run (approximations and details)",
                 fontsize=9)
    return Figure(fig, "Mallat db4 decomposition (Fang et al., spec 001, Figs. 3-4): low levels carry drift and "
                       "noise; at high levels P2 keeps the vibration bias.", "levels")


def _fig_separation(res):
    """Seed Fig. 4 analogue: the record with its bias signal A_L, the first detail D1 and
    the drift + noise x - A_L (= D1 + ... + D_L) of the decomposed run."""
    d = res.views.get("decomposition")
    if d is None:
        return None
    dec, fs, L = d["dec"], d["fs_hz"], res.level
    x = dec.approximation(0) if hasattr(dec, "approximation") else None
    a = dec.approximation(L)
    x = a + sum(dec.detail(j) for j in range(1, L + 1)) if x is None else x
    fig, axes = plt.subplots(3, 1, figsize=(9, 6.5), sharex=True)
    panels = ((x, f"raw x and bias signal A{L}", "0.5"), (dec.detail(1), "D1", "tab:purple"),
              (x - a, f"drift + noise x - A{L}", "tab:green"))
    for ax, (sig, lab, c) in zip(axes, panels):
        plot_m4_even(ax, sig, 1 / fs, lw=0.4, color=c, label=lab)
        if lab.startswith("raw"):
            plot_m4_even(ax, a, 1 / fs, lw=1.0, color="tab:blue", label=f"A{L}")
        _shade(ax, fs, d["k_on"], d["k_off"])
        ax.set_ylabel("deg/h", fontsize=8)
        ax.legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(f"Separation of the {d['run']} run (Fang et al., spec 001, Fig. 4): A{L}, D1 and x - A{L}",
                 fontsize=9)
    return Figure(fig, f"Seed Fig. 4 analogue: the level-{L} approximation is the bias "
                       f"signal; D1 (the finest detail) and x - A{L} (D1 + ... + D{L}) carry "
                       "the drift and noise.", "separation")


def _fig_waterfall(res):
    """The sweep's decomposition as a waterfall (Fang et al., spec 001, Fig. 3, 3-D time-scale view): each
    detail D_j and the final approximation, normalised, offset by level."""
    sw = res.views.get("sweep")
    if sw is None or sw.get("dec") is None:
        return None
    dec, fs = sw["dec"], sw["fs_hz"]
    fig, ax = plt.subplots(figsize=(9, 6))
    levels = list(range(1, dec.level + 1))
    for j in levels:
        sig = dec.detail(j)
        scale = np.max(np.abs(sig)) or 1.0
        plot_m4_even(ax, sig / scale * 0.45 + j, 1 / fs, lw=0.4,
                     color=plt.cm.viridis(j / (dec.level + 1)))
    a = dec.approximation(dec.level)
    a = (a - np.median(a)) / ((np.max(np.abs(a - np.median(a)))) or 1.0) * 0.45
    plot_m4_even(ax, a + dec.level + 1, 1 / fs, lw=0.8, color="k")
    ax.set_yticks(levels + [dec.level + 1])
    ax.set_yticklabels([f"D{j}" for j in levels] + [f"A{dec.level}"], fontsize=7)
    _shade(ax, fs, sw["k_on"], sw["k_off"])
    f = sw.get("freq")
    if f is not None:
        ax2 = ax.twiny()
        on = f > 0
        if on.any():
            ticks = [p for p in (1, 10, 100, 500) if f[on].min() <= p <= f[on].max()]
            pos = [float(np.argmin(np.abs(np.where(on, f, np.inf) - p))) / fs for p in ticks]
            # a fast sweep reaches 100 and 500 Hz within seconds: drop a label that would
            # touch the previous one (7-pt characters ~0.06 in wide, axes ~85 % of the width)
            per_in = np.ptp(ax.get_xlim()) / (0.85 * fig.get_figwidth())
            names = [f"{p} Hz" for p in ticks]
            keep = [0] if pos else []
            for i in range(1, len(pos)):
                need = (0.06 * (len(names[i]) + len(names[keep[-1]])) / 2 + 0.08) * per_in
                if pos[i] - pos[keep[-1]] >= need:
                    keep.append(i)
            ax2.set_xlim(ax.get_xlim())
            ax2.set_xticks([pos[i] for i in keep])
            ax2.set_xticklabels([names[i] for i in keep], fontsize=7)
    ax.set_xlabel("time [s]")
    ax.set_title("Sweep run: db4 details by level (waterfall; each trace normalised)",
                 fontsize=9)
    return Figure(fig, "Waterfall of the sweep's decomposition (Fang et al., spec 001, Fig. 3): where each level "
                       "responds as the drive frequency (top axis) rises.", "sweep_waterfall")


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
    return Figure(fig, "RBF network versus 4th-order polynomial on the bias-vs-frequency "
                       "targets of the sweep (Fang et al., spec 001, Fig. 6).", "bias_curve")


def _fig_compensated(res):
    d = res.views.get("fixed")
    if d is None:
        return None
    fs = d["fs_hz"]
    fig, ax = plt.subplots(figsize=(9, 4))
    for key, lab, c in (("approx", f"denoised A{res.level}", "tab:blue"),
                        ("poly", "polynomial-compensated", "tab:green"),
                        ("rbf", "RBF-compensated", "tab:red")):
        plot_m4_even(ax, d[key], 1 / fs, lw=0.6, color=c, label=lab)
    _shade(ax, fs, d["k_on"], d["k_off"])
    ax.set_xlabel("time [s]")
    ax.set_ylabel("rate [deg/h]")
    ax.legend(fontsize=8)
    ax.set_title("Fixed 500-Hz run after denoising and compensation")
    return Figure(fig, "Compensation of the 500-Hz run (Fang et al., spec 001, Figs. 7-8): the offset of P2 is "
                       "removed except near the vibration edges.", "compensated")


def figures(res) -> list[Figure]:
    """All figures of a :class:`~inertialab.workflows.vibration.VibrationResult`."""
    out = []
    for fn in (_fig_record, _fig_scalogram, _fig_spectra, _fig_emd, _fig_levels,
               _fig_separation, _fig_waterfall, _fig_bias, _fig_compensated):
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
    raw = res.metrics.get("raw_phases")
    if raw:
        out.append(Table(title="Raw records: bias and 10-s bias stability per phase (deg/h)",
                         columns=["record", "phase", "bias", "10-s stability"],
                         rows=[[rn, ph, v["bias"][ph], v["stability_10s"][ph]]
                               for rn, v in raw.items() for ph in v["bias"]]))
    sel_sp = f["rbf"].get("spread_selection")
    if sel_sp:
        out.append(Table(title=f"RBF spread by held-out RMSE (chosen {sel_sp['chosen']:g} Hz)",
                         columns=["spread [Hz]", "held-out RMSE [deg/h]", "neurons"],
                         rows=[[g, r, k] for g, r, k in zip(sel_sp["grid"],
                                                             sel_sp["heldout_rmse"],
                                                             sel_sp["neurons"])]))
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
