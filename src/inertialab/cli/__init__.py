"""The command line: one module per command group, each with ``register(app, groups)``.

The CLI parses, calls a workflow, prints or writes; it never computes.
"""
