"""The papers' reproductions, above the product (docs/architecture.md).

One module per study (``allan vibration thermal triaxial dual drift``): its quick and
full settings, the virtual-lab run, Monte Carlo, bootstrap and sweeps, and the
``STUDY`` object the demo runs (:mod:`inertialab.studies.base`). The only floor besides
``cli/`` that imports ``sim/``. Workflows below never import from here.
"""


def study_modules() -> tuple:
    """The study modules the demo runs (each defines ``STUDY``), imported here
    explicitly when asked for.

    Examples
    --------
    >>> [m.STUDY.name for m in study_modules()]
    ['allan', 'vibration', 'thermal', 'triaxial', 'dual', 'drift']
    """
    from inertialab.studies import allan, drift, dual, thermal, triaxial, vibration

    return (allan, vibration, thermal, triaxial, dual, drift)


__all__ = ["study_modules"]
