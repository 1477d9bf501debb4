"""The papers' reproductions, above the product (DESIGN.md "Layers", issue 13).

One module per study (``allan vibration thermal triaxial dual drift``): its quick and
full settings, the virtual-lab run, Monte Carlo, bootstrap and sweeps, and the
``STUDY`` object the demo runs (:mod:`inertialab.studies.base`). The only floor besides
``cli/`` that imports ``sim/``. Workflows below never import from here.
"""
