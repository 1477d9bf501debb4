"""Learning methods: clustering, fuzzy inference, ANFIS, RBF and LM-trained networks,
NAR forecasting, order selection, regression and forecast baselines.

Import the estimators from their modules (``inertialab.learn.poly`` ...); this package
keeps no import-time side effects.
"""
