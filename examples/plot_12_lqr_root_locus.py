"""
Figure 6.12: the regulator's root locus over the weight
=======================================================

The closed-loop roots of the lateral regulator as c grows from 0.001. The Dutch roll becomes
critically damped at the weight :func:`aerocontrol.design.critical_weight` finds by bisection;
symbols mark the chapter's values of c.
"""

import matplotlib.pyplot as plt
import numpy as np

from aerocontrol import aircraft, design, plotting

sys = aircraft.load("b747-approach").lateral()
Q, R = np.eye(4), np.eye(2)
critical = design.critical_weight(sys, "dutch roll", Q, R, bounds=(1e-3, 1e3))
print(f"critical c = {critical:.6f}")
marked = [0.001, 0.5, 1.0, 2.0, 5.0, 8.0, 9.0, 9.7, 9.76, 9.7727, 9.7728, 10.0]
weights = np.unique(np.r_[np.geomspace(1e-3, 1.2 * critical, 400), marked])
poles = design.lqr_root_locus(sys, weights, Q, R)

figure, ax = plt.subplots(figsize=(9, 5.5), layout="constrained")
plotting.plot_root_locus(weights, poles, ax=ax, marked=marked, title="closed-loop roots over c")
plt.show()
