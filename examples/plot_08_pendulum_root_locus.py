"""
Figure 6.8: the inverted pendulum's optimal root locus
======================================================

The inverted pendulum ẍ = γx + T (6.202) with γ = 1, regulated by the LQR that minimises
J = ∫ x² + T²/c² dt (6.209). As the weight c grows from 0.001 the closed-loop roots leave the
double root at -√γ and approach the asymptotes ζ = 1/√2 (6.223). Symbols mark c/γ = 0.001, 1,
10, 100 and 1000.
"""

import math

import matplotlib.pyplot as plt
import numpy as np

from aerocontrol import StateSpace, design, plotting

gamma = 1.0
pendulum = StateSpace(np.array([[0.0, 1.0], [gamma, 0.0]]), np.array([0.0, 1.0]))
weights = np.unique(np.r_[np.geomspace(1e-3, 1e3, 400), 1.0, 10.0, 100.0])
poles = design.lqr_root_locus(pendulum, weights, np.diag([1.0, 0.0]), np.eye(1))

figure, ax = plt.subplots(figsize=(6, 5.5), layout="constrained")
plotting.plot_root_locus(
    weights, poles, ax=ax, marked=[1e-3, 1.0, 10.0, 100.0, 1000.0], weight_name="c/γ"
)
reach = 1.1 * float(np.abs(poles).max())
for sign in (1.0, -1.0):
    ax.plot([0.0, -reach / math.sqrt(2)], [0.0, sign * reach / math.sqrt(2)], color="c",
            linewidth=0.8)  # fmt: skip
ax.set_aspect("equal")
plt.show()
