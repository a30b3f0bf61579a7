"""The property suite: every public function of aerocontrol on hostile inputs, against oracles.

See ``harness.py`` for the invariant each call must satisfy, ``strategies.py`` for the inputs,
and ``conftest.py`` for the hypothesis profiles and the tally of outcomes.
"""
