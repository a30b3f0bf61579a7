"""
Figure 6.11: the two terms of the performance index
===================================================

xᵀQx (solid, above) and -ηᵀRη/c² (dashed, below) against time for c = 0.5, 1 and 2: the area
between the curves is the index J, equal to x0ᵀ S x0 over an infinite horizon (6.200).
"""

import matplotlib.pyplot as plt
import numpy as np

from aerocontrol import StateSpace, aircraft, initial_response, plotting, solve_care

sys = aircraft.load("b747-approach").lateral()
x0 = np.zeros(sys.n_states)
x0[sys.state_names.index("beta")] = 1.0
grid = np.linspace(0.0, 30.0, 1501)
Q, R = np.eye(4), np.eye(2)

figure, ax = plt.subplots(figsize=(9, 4.8), layout="constrained")
for c in (0.5, 1.0, 2.0):
    solution = solve_care(sys.A, sys.B, Q, R / c**2)
    closed = StateSpace(sys.A - sys.B @ solution.K, sys.B, state_names=sys.state_names)
    response = initial_response(closed, x0, T=grid)
    plotting.plot_penalty(response, solution.K, Q, R / c**2, ax=ax, name=f"c = {c:g}")
plt.show()
