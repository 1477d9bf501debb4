"""Readers of the binary and container formats robots and rigs log in (ROS 1/2 bags,
PX4 ULog, MATLAB/HDF5), each returning a DataFrame for the one front door
(:func:`inertialab.io.read_record`). Each needs the ``[formats]`` extra; a missing
extra is a one-line :class:`~inertialab.errors.InputError` naming it.

The public face, imported on first use::

    FORMATS FileFormat formats_with_option (registry)  load_frame (dispatch)
"""

__all__ = ["FORMATS", "FileFormat", "formats_with_option", "load_frame"]


def __getattr__(name):  # PEP 562: the public face, imported on first use
    if name in ('FORMATS', 'FileFormat', 'formats_with_option',):
        from inertialab.io.formats import registry as mod
    elif name in ('load_frame',):
        from inertialab.io.formats import dispatch as mod
    else:
        raise AttributeError(f"module 'inertialab.io.formats' has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
