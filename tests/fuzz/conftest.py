"""The slow hostile set (``@pytest.mark.hostile_slow``) runs only when asked for:
``pytest -m hostile_slow tests/fuzz`` (CI does) or ``INERTIALAB_HOSTILE_SLOW=1``."""

import os

import pytest


def pytest_collection_modifyitems(config, items):
    wanted = "hostile_slow" in (config.option.markexpr or "") or \
        os.environ.get("INERTIALAB_HOSTILE_SLOW") == "1"
    if wanted:
        return
    skip = pytest.mark.skip(reason="slow hostile set: run with -m hostile_slow")
    for item in items:
        if "hostile_slow" in item.keywords:
            item.add_marker(skip)
