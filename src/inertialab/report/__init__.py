"""Figures (matplotlib) and the self-contained HTML report. The report renders; it
does not compute: every number comes from a workflow result.

The public face, imported on first use::

    figure_modules write_report (build)
"""

__all__ = ["figure_modules", "write_report"]


def __getattr__(name):  # PEP 562: the public face, imported on first use
    if name in ('figure_modules', 'write_report',):
        from inertialab.report import build as mod
    else:
        raise AttributeError(f"module 'inertialab.report' has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
