"""Study 000 reproduction: IAFSA-SCM-ANFIS temperature compensation of a quartz
accelerometer on the virtual lab (spec 000 §7, §8).

The demo (``STUDY``, settings :data:`QUICK`/:data:`FULL`): the paper preset's lot 0, unit
0 trains the seven models (ANN, FIS, ANFIS, SCM-ANFIS, IAFSA-SCM-ANFIS, POLY-SEP,
POLY-2D), unit 1 is compensated with unit 0's proposed model (§3.7 transfer), and a
bootstrap over the temperature blocks (§8.4) gives a band on the compensated drift.
:func:`virtual_lab_run` is one run of the §8.2 benchmark (two simulated units, one
split, one seed), used by ``benchmarks/thermal.py``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from inertialab.blas import single_threaded_blas
from inertialab.calib.thermal import (
    FUZZY,
    METHODS,
    Split,
    ThermalModel,
    ThermalSamples,
    drift,
    fit_model,
)
from inertialab.progress import NullProgress
from inertialab.seeding import as_generator
from inertialab.studies.base import Headline, Study, StudyResult, settings_dict
from inertialab.workflows.thermal import (
    FitConfig,
    fit_thermal,
    prepare_samples,
    strata_of,
    validation_subset,
)

#: Paper figures (spec 000 §6): test RMSE in mg.
PAPER_RMSE_MG = {"ann": 0.138, "fis": 0.101, "anfis": 0.034, "iafsa-scm-anfis": 0.004}


# ---------------------------------------------------------------------------------------
# bootstrap uncertainty (spec 000 §8.4)
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class BootstrapResult:
    """Bootstrap over set-point blocks: ``std_ug`` of the compensated output per sample,
    ``band_lo_ug``/``band_hi_ug`` = 2.5/97.5 % of the compensated drift per sample,
    ``n_boot`` replicas, ``method``."""

    std_ug: np.ndarray
    band_lo_ug: np.ndarray
    band_hi_ug: np.ndarray
    n_boot: int
    method: str

    def summary(self) -> dict:
        return {"n_boot": self.n_boot, "method": self.method,
                "median_std_ug": float(np.median(self.std_ug)),
                "max_band_halfwidth_ug": float(np.max(self.band_hi_ug - self.band_lo_ug) / 2)}


def bootstrap(samples: ThermalSamples, model: ThermalModel, config: FitConfig, *,
              n_boot: int = 50, epochs: int | None = None, rng=None) -> BootstrapResult:
    """Resample the temperature blocks (set points, the reference always kept) with
    replacement, refit ``model.method`` with its SCM parameters fixed, and collect the
    compensated drift of every sample (spec 000 §8.4)."""
    cfg = replace(config, epochs=epochs if epochs is not None else config.epochs)
    g = as_generator(rng)
    sps = np.unique(samples.set_point_c)
    is_ref = np.isclose(sps, cfg.reference_temp_c, atol=1e-6)
    others = sps[~is_ref]
    ref_sp = sps[is_ref]
    preds = []
    for _ in range(n_boot):
        pick = np.concatenate([ref_sp, g.choice(others, size=others.size, replace=True)])
        idx = np.concatenate([np.flatnonzero(samples.set_point_c == s) for s in pick])
        strata = strata_of(samples)
        fit, val = validation_subset(idx, strata, cfg.val_fraction, g)
        # a resampled block appears more than once: keep duplicates in fit, val from distinct
        sp = Split("bootstrap", idx, np.arange(samples.n), fit if fit.size else idx, val)
        with single_threaded_blas():
            m = fit_model(samples, sp, model.method, cfg, rng=g, scm_params=model.scm)
        d = drift(m, samples, own_unit=True)
        preds.append(d.comp_ug)
    P = np.asarray(preds)
    return BootstrapResult(std_ug=P.std(axis=0, ddof=1), band_lo_ug=np.percentile(P, 2.5, axis=0),
                           band_hi_ug=np.percentile(P, 97.5, axis=0), n_boot=int(n_boot),
                           method=model.method)



# ---------------------------------------------------------------------------------------
# one benchmark run (spec 000 §8.2)
# ---------------------------------------------------------------------------------------
def virtual_lab_run(preset: str, seed: int, split: str, config_kw: dict | None = None,
                    *, lot_seed: int = 0) -> dict:
    """One run of the §8.2 benchmark: unit 0 of lot ``lot_seed`` (run seed ``seed``)
    trains every model on ``split``; unit 1 (run seed ``seed + 1000``) is compensated with
    the proposed model. Returns JSON-ready numbers: metrics per model, the search log,
    transfer and own-unit drift, the record's noise floor, wall and CPU seconds."""
    from inertialab.sim.thermal_tumble import simulate

    run_a = simulate(preset, lot_seed, 0, seed=seed)
    run_b = simulate(preset, lot_seed, 1, seed=seed + 1000)
    cfg = FitConfig(method="all", split=split, seed=seed, **(config_kw or {}))
    sa = prepare_samples(run_a.frame, cfg)
    sb = prepare_samples(run_b.frame, cfg)
    t0, c0 = time.perf_counter(), time.process_time()
    fit = fit_thermal(sa, cfg)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    best = fit.models["iafsa-scm-anfis"]
    tr = drift(best, sb)
    own = drift(best, sa, own_unit=True)
    s = fit.search
    return {
        "preset": preset, "run_seed": seed, "split": split,
        "noise_floor_ug": run_a.noise_floor_ug, "raw_rms_ug": fit.raw_rms_ug,
        "models": fit.table(),
        "search": {k: s[k] for k in ("params", "fun", "f_default", "n_rules", "nfev", "nit",
                                     "wall_s", "message")},
        "transfer": tr.summary(), "own_unit": own.summary(),
        "transfer_clamped": int(np.count_nonzero(tr.status)),
        "fit_wall_s": wall, "fit_cpu_s": cpu,
    }


# ---------------------------------------------------------------------------------------
# demo study
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class QuickSettings:
    """Demo settings (quick: <= 8 s on 2 cores): paper preset, lot seed 0, unit 0 trains,
    unit 1 is the transfer unit; a shortened IAFSA (6 fish, 6 generations, 10-epoch
    objective) and 60 final epochs; no bootstrap."""

    preset: str = "paper"
    lot_seed: int = 0
    run_seed: int = 0
    split: str = "random"
    methods: tuple[str, ...] = METHODS
    fish: int = 6
    generations: int = 5
    search_epochs: int = 10
    epochs: int = 60
    ann_max_epochs: int = 100
    n_boot: int = 0
    boot_epochs: int = 20


@dataclass(frozen=True)
class FullSettings(QuickSettings):
    """Full demo (<= 25 s): 8 fish x 10 generations, 20-epoch objective, 150 final epochs,
    ANN up to 500 LM iterations, 10 bootstrap replicas of 20 epochs."""

    fish: int = 8
    generations: int = 10
    search_epochs: int = 20
    epochs: int = 150
    ann_max_epochs: int = 500
    n_boot: int = 10


def run_demo(settings=None, progress=None) -> StudyResult:
    """The thermal study on the virtual lab (for ``inertialab demo``)."""
    from inertialab.sim.thermal_tumble import simulate

    st = settings or QuickSettings()
    progress = progress or NullProgress()
    t0 = time.perf_counter()
    run_a = simulate(st.preset, st.lot_seed, 0, seed=st.run_seed)
    run_b = simulate(st.preset, st.lot_seed, 1, seed=st.run_seed + 1000)
    cfg = FitConfig(method=tuple(st.methods), split=st.split, fish=st.fish,
                    generations=st.generations, search_epochs=st.search_epochs,
                    epochs=st.epochs, ann_max_epochs=st.ann_max_epochs, seed=st.run_seed)
    sa = prepare_samples(run_a.frame, cfg)
    sb = prepare_samples(run_b.frame, cfg)
    fit = fit_thermal(sa, cfg, progress=progress)
    best = "iafsa-scm-anfis" if "iafsa-scm-anfis" in fit.models else next(iter(fit.models))
    model = fit.models[best]
    own = drift(model, sa, own_unit=True)
    transfer = drift(model, sb)
    boot = None
    if st.n_boot > 0 and best in FUZZY:
        boot = bootstrap(sa, model, cfg, n_boot=st.n_boot, epochs=st.boot_epochs, rng=st.run_seed)
    tables = {
        "models": fit.table(),
        "raw_rms_ug": fit.raw_rms_ug,
        "noise_floor_ug": run_a.noise_floor_ug,
        "search": fit.search,
        "transfer": transfer.summary(),
        "own_unit": own.summary(),
        "bootstrap": boot.summary() if boot else None,
    }
    head = [Headline(f"test RMSE {m.upper()}", round(fit.metrics[m].rmse_ug, 2),
                     None if m not in PAPER_RMSE_MG else PAPER_RMSE_MG[m] * 1e3, "µg")
            for m in fit.metrics]
    head.append(Headline("transfer max drift (unit 1)", round(transfer.comp_max_ug, 1), 9.3, "µg"))
    text = [
        f"Virtual lab, {st.preset} preset, lot seed {st.lot_seed}: unit 0 trains the models "
        f"({st.split} split, 23 set points x 24 positions), unit 1 is compensated with unit 0's "
        f"{best.upper()} model. Noise floor of the record: {run_a.noise_floor_ug:.1f} µg.",
        "The paper reports test RMSE 0.138 / 0.101 / 0.034 / 0.004 mg for ANN / FIS / ANFIS / "
        "IAFSA-SCM-ANFIS and a transfer drift of 9.3 µg; the ordering, not the exact numbers, "
        "is the reproduction target (split ratio, fish parameters and ANN structure are lost).",
    ]
    data = {"fit": fit, "samples": sa, "samples_b": sb, "own": own, "transfer": transfer,
            "bootstrap": boot, "best": best}
    return StudyResult(name="thermal", title="Quartz accelerometer temperature drift (spec 000)",
                       settings=settings_dict(st) | {"config": settings_dict(cfg)}, headline=head,
                       tables=tables, data=data, text=text, wall_s=time.perf_counter() - t0)


QUICK = QuickSettings()
FULL = FullSettings()
STUDY = Study(name="thermal", title="Quartz accelerometer temperature drift (spec 000)",
              quick=QUICK, full=FULL, run=run_demo)


__all__ = ["FULL", "PAPER_RMSE_MG", "QUICK", "STUDY", "BootstrapResult", "FullSettings",
           "QuickSettings", "bootstrap", "run_demo", "virtual_lab_run"]
