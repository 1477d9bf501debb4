"""The command line: one module per command group, each with ``register(app, groups)``.

The CLI parses, calls a workflow, prints or writes; it never computes.

The public face, imported on first use::

    build_app full_command (main: ``python -m inertialab`` runs ``inertialab.cli.main.main``)
"""

__all__ = ["build_app", "full_command"]


def __getattr__(name):  # PEP 562: the public face, imported on first use
    if name in ('build_app', 'full_command'):
        from inertialab.cli import main as mod
    else:
        raise AttributeError(f"module 'inertialab.cli' has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
