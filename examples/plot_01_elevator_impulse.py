"""
Figure 6.1: response to an elevator impulse
===========================================

The Boeing 747 in powered approach (M = 0.25, sea level), longitudinal model (6.49), after a
unit elevator impulse (1 rad s). The left panel shows the first 20 s (the short period), the
right one 500 s (the phugoid). The response is x(t) = e^{At} B, exact at every sample (6.40).
"""

import matplotlib.pyplot as plt
import numpy as np

import aerocontrol
from aerocontrol import plotting

A, B = aerocontrol.chapter.boeing747_longitudinal()
sys = aerocontrol.StateSpace(
    A, B, state_names=["u/u0", "alpha", "q", "theta"], input_names=["elevator"]
)
impulse = aerocontrol.impulse_response(sys, T=np.linspace(0.0, 500.0, 10001))

figure, axes = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
plotting.plot_time_scales(impulse, 20.0, axes=axes)
plt.show()
