"""
Figure 6.9: the optimal regulator with expensive control
========================================================

The 747's lateral model regulated by the LQR with Q = I, R = I/c² and both surfaces
(6.224)-(6.227), after a unit sideslip perturbation: (a) open loop, (b) c = 0.001, where
control is so expensive that the regulator only stabilises the spiral mode. The control
deflections η = -Kx are dashed.
"""

import matplotlib.pyplot as plt
import numpy as np

from aerocontrol import StateSpace, aircraft, initial_response, plotting, solve_care

sys = aircraft.load("b747-approach").lateral()
x0 = np.zeros(sys.n_states)
x0[sys.state_names.index("beta")] = 1.0
grid = np.linspace(0.0, 30.0, 1501)
c = 0.001
solution = solve_care(sys.A, sys.B, np.eye(4), np.eye(2) / c**2)
closed = StateSpace(sys.A - sys.B @ solution.K, sys.B, state_names=sys.state_names)
print("J∞ = x0ᵀ S x0 =", round(float(x0 @ solution.X @ x0), 4))

figure, axes = plt.subplots(1, 2, figsize=(11, 4.4), sharey=True, layout="constrained")
plotting.plot_time_response(initial_response(sys, x0, T=grid), ax=axes[0], title="(a) no feedback")
plotting.plot_with_controls(
    initial_response(closed, x0, T=grid), solution.K, ax=axes[1], title=f"(b) c = {c:g}"
)
plt.show()
