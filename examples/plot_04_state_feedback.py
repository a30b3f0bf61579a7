"""
Figure 6.4: the effect of state feedback
========================================

The second-order example (6.94): A = [[-3, 8], [0, 0]], b = [0, 4]ᵀ, with eigenvalues -3 and 0.
The feedback η = -kᵀx of Bass and Gura's formula (6.93) places ω_n = 25 1/s and ζ = 0.707; the
gains are the chapter's k = [16.5, 8.09] (6.102). Panel (a) starts from x(0) = [1, 0], panel
(b) from x(0) = [1, 0.1].
"""

import math

import matplotlib.pyplot as plt
import numpy as np

import aerocontrol
from aerocontrol import plotting

A, B = aerocontrol.chapter.state_feedback_example()
zeta, omega_n = 0.707, 25.0
pole = complex(-zeta * omega_n, omega_n * math.sqrt(1.0 - zeta**2))
design = aerocontrol.place_bass_gura(A, B, [pole, pole.conjugate()])
print("k =", np.round(design.k, 4))

original = aerocontrol.StateSpace(A, B, state_names=["x1", "x2"])
feedback = aerocontrol.StateSpace(design.closed_loop, B, state_names=["x1", "x2"])
figure, axes = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
for ax, x0, final, panel in zip(axes, ([1.0, 0.0], [1.0, 0.1]), (2.0, 5.0), "ab", strict=True):
    grid = np.linspace(0.0, final, 2001)
    plotting.plot_time_response(
        aerocontrol.initial_response(original, x0, T=grid), ax=ax, suffix=", original system"
    )
    plotting.plot_time_response(
        aerocontrol.initial_response(feedback, x0, T=grid),
        ax=ax,
        suffix=", with feedback",
        linestyle="--",
        title=f"({panel}) x(0) = {x0}",
    )
plt.show()
