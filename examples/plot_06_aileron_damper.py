"""
Figure 6.6: a Dutch-roll damper with the aileron
================================================

The 747's lateral model after a 5-degree sideslip perturbation: (a) open loop, (b) with the
Dutch roll's damping raised to ζ = 0.3 by aileron state feedback (Bass-Gura, leaving the
other modes in place; the chapter's gains are (6.164)).
"""

import math

import matplotlib.pyplot as plt
import numpy as np

from aerocontrol import StateSpace, aircraft, design, initial_response, plotting

sys = aircraft.load("b747-approach").lateral()
damper = design.dutch_roll_damper(sys, zeta=0.3, surface="aileron")
print("k =", np.round(damper.k, 4))

x0 = np.zeros(sys.n_states)
x0[sys.state_names.index("beta")] = math.radians(5.0)
grid = np.linspace(0.0, 30.0, 1501)
column = sys.B[:, [sys.input_names.index("aileron")]]
closed = StateSpace(sys.A - column @ damper.K, sys.B, state_names=sys.state_names)
figure, axes = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
plotting.plot_open_closed(
    initial_response(sys, x0, T=grid),
    initial_response(closed, x0, T=grid),
    axes=axes,
    titles=("(a) open loop", "(b) damper, aileron feedback"),
)
plt.show()
