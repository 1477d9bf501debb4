"""The product models, one module each (DESIGN.md "Layers", issue 13).

``triaxial`` (accelerometer + gyro field/turntable calibration, spec 002), ``ferraris``
(six faces + rotations), ``thermal`` (spec 000) and ``thermal_export``, ``dual``
(spec 003), ``vibration`` (spec 001), ``drift`` (spec 004). Each holds the estimator on
arrays (no files, no records), its fitted artefact with ``to_dict``/``from_dict``, its
units, a per-type format version and plausibility checks. Imports the method floor
(``noise learn optim regress sensors metrics``) and nothing above.
"""
