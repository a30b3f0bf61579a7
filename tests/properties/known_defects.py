"""Defects of the native core that the property suite found, kept until the Rust is fixed.

None is known today: every defect the campaigns found has been fixed and its reproduction
turned into a regression test (``test_regression_*`` and the tests under "inputs a campaign
found"). A new one is registered here with ``known_defect(...)``, as before.

Each defect names the public functions it affects and the inputs it concerns: a predicate on
the canonical arguments, as narrow as the measurements allowed. While it is known, a failed
check on such an input is counted as ``known defect <key>`` and does not fail the property, so
that the rest of the property keeps running in CI and in long campaigns. Each defect also has
a reproduction, a test marked ``xfail(strict=True)`` beside the property that found it
(``test_known_defect_*``), which runs the minimal input with the allowance switched off: when
the core is fixed it passes, the strict xfail fails, and the entry here is to be removed.
"""

from __future__ import annotations
