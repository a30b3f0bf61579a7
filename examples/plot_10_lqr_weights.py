"""
Figure 6.10: the regulator as control gets cheaper
==================================================

The same regulator for c = 0.5, 1 and 2: the larger c, the faster the sideslip dies out and
the larger the deflections (dashed).
"""

import matplotlib.pyplot as plt
import numpy as np

from aerocontrol import StateSpace, aircraft, initial_response, plotting, solve_care

sys = aircraft.load("b747-approach").lateral()
x0 = np.zeros(sys.n_states)
x0[sys.state_names.index("beta")] = 1.0
grid = np.linspace(0.0, 30.0, 1501)

figure, axes = plt.subplots(1, 3, figsize=(15, 4.4), sharey=True, layout="constrained")
for ax, c in zip(axes, (0.5, 1.0, 2.0), strict=True):
    solution = solve_care(sys.A, sys.B, np.eye(4), np.eye(2) / c**2)
    closed = StateSpace(sys.A - sys.B @ solution.K, sys.B, state_names=sys.state_names)
    plotting.plot_with_controls(
        initial_response(closed, x0, T=grid), solution.K, ax=ax, title=f"c = {c:g}"
    )
plt.show()
