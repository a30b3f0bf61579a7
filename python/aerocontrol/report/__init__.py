"""The report of the chapter's analyses on one aircraft: what ``aerocontrol report`` writes.

:func:`build_report` runs the analyses of the course chapter on an aircraft (the embedded 747
by default) and collects the results as a :class:`Report` of headings, paragraphs, tables and
matplotlib figures; :func:`write_report` renders it into a folder as ``report.html`` (self-
contained: the figures are embedded) and ``report.md`` with ``figures/*.png``. The sections:

1. the flight condition and the models (6.49, 6.150);
2. the modes (6.152-6.154) and their MIL-F-8785C Levels;
3. the elevator impulse and step at the chapter's two time scales (Figures 6.1, 6.2), the
   steady state of the step (6.51), rudder and aileron steps, and Bode plots;
4. the Dutch-roll damper by Bass-Gura with rudder and with aileron: the characteristic
   polynomials, companion-form gains, gains and closed-loop matrices (6.155-6.165, Figures 6.5,
   6.6);
5. the lateral regulator at the chapter's weights c (6.224-6.227, Figures 6.9-6.11), its root
   locus over c with the weight at which the Dutch roll becomes critically damped (Figure 6.12);
6. the lateral designs on a flight computer: the regulator (c = 1) by dlqr with the sampled
   weights and the rudder damper placed at the mapped roots, at 50 Hz and 10 Hz, beside the
   continuous designs and their gains held (roots s = ln(z)/T, the Dutch roll's ζ and ω_n, the
   gain difference, the continuous cost); an LQG regulator at 50 Hz with sideslip not
   measured (a Kalman filter from p, r, φ), its closed-loop poles and its response beside
   full-state feedback;
7. stability augmentation by output feedback: a yaw damper (yaw rate to rudder through an
   actuator, with and without a washout) and a pitch damper designed on the root locus, their
   margins against MIL-F-9490D (Table I as widely quoted, every cell unverified), the root
   locus and the response to a rudder pulse beside the open loop's;
8. the Levels after augmentation, and the open-loop Levels over Mach and altitude around the
   file's condition;
9. for the embedded 747, the chapter's small examples (controllability (6.75-6.88), Figures 6.4
   and 6.8) and its printed numbers beside ours, among them the static check (6.52-6.55).

A design that does not apply to an aircraft (for example a lateral model without an
oscillatory Dutch roll) is reported as such and the rest of the report goes on.

The package's modules, for a contributor: ``build`` (the two entry
points), ``document`` and ``render`` (the
document and its Markdown, HTML and PNG forms), ``context`` and
``formatting`` (what the sections share), one module per section
(``models``, ``modes``,
``responses``, ``damper``,
``regulator``, ``digital``,
``sas``, ``levels``,
``envelope``, ``chapter_check``), and the output
folder: ``folder`` (the rules and ``ReportFolder``),
``manifest``, ``staging``,
``descriptors`` and ``signals``. The public API
is what this package exports.

Examples
--------
>>> from aerocontrol.report import build_report
>>> report = build_report("b747-approach", progress=print)   # doctest: +ELLIPSIS
models: Boeing 747, powered approach, longitudinal ('u/u0', 'alpha', 'q', 'theta'), ...
modes: phugoid -0.001774 + 0.1339j; short period -0.5514 + 0.6879j; spiral -0.04641; ...
handling qualities (Levels): short period 1, phugoid 2, dutch roll 2, roll 1, spiral 1
responses: elevator impulse and step over 20 s and 500 s (Figures 6.1, 6.2), ...
Dutch-roll damper (Bass-Gura): rudder k = [0.1383, 0.09435, 0.125, -1.133], ...
LQR (Figures 6.9-6.11): c = 0.001: J∞ = 16.57; c = 0.5: J∞ = 10.56; c = 1: J∞ = 7.088; ...
root locus (Figure 6.12): The Dutch roll becomes critically damped at c = 9.772714 ...
digital regulator (c = 1): 50 Hz: ‖K - K_c‖/‖K_c‖ = 6.377e-03, Dutch roll ζ = 0.35955; ...
digital damper (rudder): 50 Hz: k = [0.1316, 0.09474, 0.1248, -1.128], ...
LQG (50 Hz, p, r, phi measured): filter poles 0.9902 + 0.00251j, 0.9337, 0.9553; J = 9.902 ...
output-feedback dampers: yaw damper, washout 3 s: k = 2.413, ζ = 0.256; ...
levels after augmentation: dutch roll 2 -> damper (rudder) 1, damper (aileron) 1, ...
envelope: 63 conditions around the file's (Level 2: 41, Level 3: 20, Level 4: 2)
chapter check: Figures 6.4 and 6.8, 16 results beside the printed values
>>> len(report.figures)
17
"""

from __future__ import annotations

from .build import build_report, write_report
from .damper import DAMPER_SIDESLIP as DAMPER_SIDESLIP
from .damper import DAMPER_ZETA as DAMPER_ZETA
from .document import Report
from .regulator import CHAPTER_WEIGHTS, LOCUS_WEIGHTS
from .responses import ONE_DEGREE as ONE_DEGREE

__all__ = ["CHAPTER_WEIGHTS", "LOCUS_WEIGHTS", "Report", "build_report", "write_report"]
