"""aerocontrol against its peers (scipy, python-control with slycot, numpy), timed in one process.

``benches/compare_peers.py`` is the command line. This package holds :mod:`peers.harness`
(what a case is, agreement, timing, thread settings, the text, JSON and Markdown reports),
:mod:`peers.inputs` (input builders several case files share) and one case file per
aerocontrol module: ``linalg``, ``responses``, ``frequency``, ``loops``, ``modal``, ``placement``,
``controllability``, ``riccati``, ``batch`` and ``accelerate``.

Coverage
--------
Every public numerical operation that has a peer in scipy, python-control (with slycot) or
numpy, at n = 4 (the 747 where it is natural), 16, 64 and 256 (expm also 8 and 1024; the batch
API on 1000 problems): expm (one matrix and a stack), transition_matrix, discretize, schur
(plain and reordered) [linalg]; the step, impulse, doublet, initial-condition and forced
responses, steady_state, dc_gain [responses]; frequency_response [frequency]; stability_margins
of the 747 dampers' loops, root_locus over 1000 gains, transfer_function of every channel
[loops]; modes, charpoly [modal]; place_bass_gura, place_ackermann, place, companion_form
[placement]; is_controllable, is_observable, controllability, ctrb, obsv [controllability]; lqr,
solve_care (with S and E), riccati_ode, lqr_finite, solve_lyapunov [riccati]; batch.lqr_sweep,
batch.solve_care_batch [batch]; python-control's lqr, lqe, place, ctrb and dlqr accelerated by
accelerate_control against as installed [accelerate]. Where a size is capped (single-input
placement and the companion form: conditioning; KNV0 placement and the Riccati ODE: the peer's
time and accuracy) the group's docstring says why. Not here, having no peer: bode
(frequency_response on a default grid), default_time_grid, default_frequency_grid, augment_mode,
the design module (compositions of the above), the aircraft module (atmosphere, models;
envelope_sweep is timed by benches/batch_scaling.py), handling and the report.

Adding a case
-------------
In the case file named after the operation's aerocontrol module, write a function
``<operation>_cases()`` that returns a list of :class:`~peers.harness.Case`, with a docstring
that describes the inputs and the peers, and add it to the file's ``GROUPS``; it becomes the
group ``<module>.<operation>``. A case has a ``setup(rng)`` that returns the tuple of
positional inputs, ``ours(*inputs)``, and one or more :class:`~peers.harness.Peer` whose
``compare(ours_output, peer_output)`` maps both outputs onto pairs of arrays that must agree.
Performance goals of an issue are :class:`~peers.harness.Target` objects attached to a
(case, peer) row. A new case file goes into ``MODULES``.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterable

from .harness import Group, group_of

MODULES = (
    "linalg",
    "responses",
    "frequency",
    "loops",
    "modal",
    "placement",
    "controllability",
    "riccati",
    "batch",
    "accelerate",
)
"""The case files, in the order a run goes through them."""


def all_groups() -> list[Group]:
    """Every group of every case file, in run order."""
    groups = []
    for module in MODULES:
        builders = importlib.import_module(f"{__name__}.{module}").GROUPS
        groups += [group_of(module, build) for build in builders]
    return groups


def select(names: Iterable[str]) -> list[Group]:
    """The groups named (``riccati.lqr``) or in the case files named (``riccati``), in run
    order; every group when ``names`` is empty. An unknown name raises ValueError."""
    wanted = {name.strip() for name in names if name.strip()}
    groups = all_groups()
    if not wanted:
        return groups
    known = set(MODULES) | {group.name for group in groups}
    unknown = sorted(wanted - known)
    if unknown:
        raise ValueError(
            f"unknown group or case file {', '.join(unknown)}; "
            f"known: {', '.join(MODULES)} and {', '.join(group.name for group in groups)}"
        )
    return [group for group in groups if group.name in wanted or group.module in wanted]
