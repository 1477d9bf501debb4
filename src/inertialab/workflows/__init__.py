"""Workflows: one module per study (allan, vibration, thermal, triaxial,
dual_tumble, storage_drift) plus the demo runner. Each offers ``fit(records, config)``
-> result and ``apply``/``compensate``; each demo-able study exposes a module-level
``STUDY`` (:class:`inertialab.workflows.base.Study`) that the demo discovers."""
