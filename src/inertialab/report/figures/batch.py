"""Figure of a batch run: one histogram per checked figure with its limits, and the yield."""

from __future__ import annotations

import math

import numpy as np

from inertialab.report.section import Figure, Section, Table


def batch_figure(result) -> Figure:
    """Histograms of the checked key figures (limits dashed) and a pass/fail/error bar."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = []
    for c in result.checks:
        if c.key not in keys:
            keys.append(c.key)
    if not keys:
        keys = [k for k in result.figure_keys() if k not in ("n_samples", "n_positions",
                                                              "rate_hz")][:3]
    ncol = len(keys) + 1
    fig, axes = plt.subplots(1, ncol, figsize=(3.2 * ncol, 3.0), squeeze=False)
    for ax, key in zip(axes[0], keys):
        v = result.values(key)
        v = v[np.isfinite(v)]
        if v.size:
            ax.hist(v, bins=min(30, max(5, int(math.sqrt(v.size)))), color="#4c72b0")
        for c in result.checks:
            if c.key != key:
                continue
            for lim in (c.lo, c.hi):
                if math.isfinite(lim):
                    ax.axvline(lim, color="#c44e52", ls="--")
                    if c.abs:
                        ax.axvline(-lim, color="#c44e52", ls="--")
        ax.set_xlabel(key)
        ax.set_ylabel("units")
    c = result.counts
    ax = axes[0][-1]
    ax.bar(["pass", "fail", "error"], [c["pass"], c["fail"], c["error"]],
           color=["#55a868", "#c44e52", "#8c8c8c"])
    ax.set_title(f"yield {100 * result.yield_fraction:.1f} % of {len(result.units)}")
    return Figure(figure=fig, caption=f"{result.command}: key figures against the tolerance "
                  "(dashed) and the lot's yield", name="batch")


def section(result) -> Section:
    """A report section for a :class:`~inertialab.workflows.batch.BatchResult`."""
    s = result.summary()
    rows = [[k, v["mean"], v["sd"], v["min"], v["max"]] for k, v in s["figures"].items()]
    return Section(key="batch", title=f"Batch: {result.command}",
                   paragraphs=[f"{s['n_units']} units, {s['n_pass']} pass, {s['n_fail']} fail, "
                               f"{s['n_error']} could not be processed."],
                   tables=[Table("Key figures over the lot", ["figure", "mean", "sd", "min",
                                                                "max"], rows)],
                   figures=[batch_figure(result)], results=s)
