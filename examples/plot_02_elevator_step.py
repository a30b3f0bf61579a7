"""
Figure 6.2: response to a one-degree elevator step
==================================================

The same 747 after a one-degree elevator step, over 20 s and 500 s. The response tends to the
steady state x = -A⁻¹ B η0 (6.45, 6.51), printed below.
"""

import math

import matplotlib.pyplot as plt
import numpy as np

import aerocontrol
from aerocontrol import plotting

A, B = aerocontrol.chapter.boeing747_longitudinal()
sys = aerocontrol.StateSpace(
    A, B, state_names=["u/u0", "alpha", "q", "theta"], input_names=["elevator"]
)
one_degree = math.radians(1.0)
step = aerocontrol.step_response(sys, T=np.linspace(0.0, 500.0, 10001), eta0=one_degree)
print("steady state (6.51):", np.round(aerocontrol.steady_state(sys, one_degree), 4))

figure, axes = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
plotting.plot_time_scales(step, 20.0, axes=axes)
plt.show()
