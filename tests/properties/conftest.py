"""Hypothesis profiles of the property suite, and the tally of outcomes.

Profiles:

* ``ci`` (the default): a bounded budget, the same examples on every run (derandomised, no
  example database), so that CI is reproducible and the suite stays within its time budget;
* ``fuzz``: ``AEROCONTROL_FUZZ_EXAMPLES`` examples per property (default 1000), random, with
  the example database in ``AEROCONTROL_FUZZ_DATABASE`` (a folder; none when unset). Chosen
  by setting ``AEROCONTROL_FUZZ_EXAMPLES`` or ``HYPOTHESIS_PROFILE=fuzz``;
  ``scripts/fuzz.sh`` does both.

With ``AEROCONTROL_FUZZ_REPORT=path`` the tally (per public function, the number of calls by
outcome: ``ok``, ``ok + <warnings>``, the exception's class, ``FAILED``) is written to ``path``
as JSON at the end of the session.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings
from hypothesis.database import DirectoryBasedExampleDatabase

from . import known_defects  # noqa: F401  (registers the known defects)
from .harness import PUBLIC_FUNCTIONS, TALLY

CI_EXAMPLES = 30

settings.register_profile(
    "ci",
    max_examples=CI_EXAMPLES,
    deadline=None,
    derandomize=True,
    database=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

_database = os.environ.get("AEROCONTROL_FUZZ_DATABASE")
settings.register_profile(
    "fuzz",
    max_examples=int(os.environ.get("AEROCONTROL_FUZZ_EXAMPLES", "1000")),
    deadline=None,
    database=DirectoryBasedExampleDatabase(_database) if _database else None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


@pytest.fixture(autouse=True)
def _every_digit() -> Iterator[None]:
    """Failing examples are printed with every digit, so that they can be reproduced (within
    the property tests only: the doctests elsewhere print with numpy's defaults)."""
    with np.printoptions(precision=17):
        yield


settings.load_profile(
    os.environ.get(
        "HYPOTHESIS_PROFILE", "fuzz" if "AEROCONTROL_FUZZ_EXAMPLES" in os.environ else "ci"
    )
)


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    path = os.environ.get("AEROCONTROL_FUZZ_REPORT")
    if not path:
        return
    report = {
        "profile": settings.get_current_profile_name(),
        "max_examples": settings.default.max_examples,
        "exit_status": int(exitstatus),
        "functions": {name: dict(sorted(TALLY[name].items())) for name in sorted(PUBLIC_FUNCTIONS)},
    }
    Path(path).write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
