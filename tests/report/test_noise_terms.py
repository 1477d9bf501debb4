"""Figures of the noise-term fit and the GMWM."""

from __future__ import annotations

import numpy as np

from inertialab.noise.gmwm import fit as G
from inertialab.noise.statistics import allan as A
from inertialab.noise.terms.fit import fit_noise_terms
from inertialab.report.figures.noise_terms import allan_terms_figure, gmwm_figure


def test_figures_draw_terms_only_over_their_ranges(tmp_path):
    rng = np.random.default_rng(0)
    fs, n = 10.0, 2**16
    y = rng.standard_normal(n) + np.cumsum(rng.standard_normal(n)) * 0.003
    r = A.oadev(y, rate_hz=fs)
    t = fit_noise_terms(r, unit="dph", n_boot=20)
    f = allan_terms_figure(r, t)
    ax = f.figure.axes[0]
    labels = [line.get_label() for line in ax.lines]
    assert any(lab.startswith("N = ") for lab in labels)
    assert any("textbook B" in lab for lab in labels)
    n_line = next(line for line in ax.lines if line.get_label().startswith("N = "))
    x = n_line.get_xdata()
    assert x.min() >= t.N.tau_range_s[0] * 0.99 and x.max() <= t.N.tau_range_s[1] * 1.01
    f.figure.savefig(tmp_path / "a.png")
    fit = G.fit_gmwm(y, fs, n_boot=0, max_gm=1)
    g = gmwm_figure(fit)
    kinds = [line.get_label().split(" ")[0] for line in g.figure.axes[0].lines]
    for p in fit.processes:
        assert p.kind in kinds
    g.figure.savefig(tmp_path / "g.png")
    assert (tmp_path / "g.png").stat().st_size > 1000
