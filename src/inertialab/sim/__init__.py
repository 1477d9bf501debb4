"""inertialab.sim: the virtual lab, one rig per study, writing records in the real schemas.

The public face, imported on first use (each rig's own module holds the rest)::

    simulate_ferraris (ferraris_session)  simulate_storage_batch (drift)
    simulate_two_orientation (dual)
"""

__all__ = ["simulate_ferraris", "simulate_storage_batch", "simulate_two_orientation"]


def __getattr__(name):  # PEP 562: the public face, imported on first use
    if name in ('simulate_ferraris',):
        from inertialab.sim import ferraris_session as mod
    elif name in ('simulate_storage_batch',):
        from inertialab.sim import drift as mod
    elif name in ('simulate_two_orientation',):
        from inertialab.sim import dual as mod
    else:
        raise AttributeError(f"module 'inertialab.sim' has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
