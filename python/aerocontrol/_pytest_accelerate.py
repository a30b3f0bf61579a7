"""A pytest plugin that runs a test session on python-control accelerated by aerocontrol.

``python -m pytest -p aerocontrol._pytest_accelerate ...`` calls
:func:`~aerocontrol.accelerate_control` when pytest is configured, before any test module is
collected (so names that test modules import from python-control are aerocontrol's), and
:func:`~aerocontrol.restore_control` when it is done. If the environment variable
``AEROCONTROL_ACCELERATE_CALLS`` names a file, the calls of each replaced function (answered by
aerocontrol, or passed to python-control's original) are written there as JSON at the end
(:func:`aerocontrol.accelerate.kernel_calls`).
"""

from __future__ import annotations

import json
import os

import pytest

from .accelerate import accelerate_control, kernel_calls, restore_control

#: The environment variable naming the file that receives the call counts.
CALLS_FILE_VARIABLE = "AEROCONTROL_ACCELERATE_CALLS"


def pytest_configure(config: pytest.Config) -> None:
    """Accelerate python-control before collection."""
    accelerate_control()


def pytest_unconfigure(config: pytest.Config) -> None:
    """Write the call counts (if asked) and restore python-control."""
    path = os.environ.get(CALLS_FILE_VARIABLE)
    if path:
        with open(path, "w", encoding="utf-8") as stream:
            json.dump(kernel_calls(), stream, indent=1, sort_keys=True)
    restore_control()
