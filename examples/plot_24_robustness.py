"""
Stochastic robustness of the Dutch-roll damping
===============================================

The 747's lateral derivatives scattered by 20 % (normal, relative), 20,000 samples, open loop
and with the chapter's LQR (c = 1) re-designed for every sample
(:func:`aerocontrol.robustness.monte_carlo`). The histogram of the Dutch roll's damping ratio
with the MIL-F-8785C Level limits, the probability that it meets Level 1 with its
Clopper-Pearson interval, and the derivatives the failures are most sensitive to.
"""

import matplotlib.pyplot as plt

from aerocontrol import aircraft, plotting
from aerocontrol.robustness import Lqr, Normal, Uncertainty, monte_carlo

plane = aircraft.load("b747-approach")
names = ["Cy_beta", "Cl_beta", "Cl_p", "Cl_r", "Cn_beta", "Cn_p", "Cn_r", "Cn_dr"]
uncertainty = Uncertainty({name: Normal(0.2) for name in names})
result = monte_carlo(plane, uncertainty, 20_000, Lqr(1.0), axis="lateral", seed=1)
for loop in ("open", "closed"):
    print(
        loop, "loop, Dutch roll meets Level 1:", result.probability("level", "dutch roll", 1, loop)
    )

figure, axes = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
plotting.plot_robustness_histogram(result, "dutch roll", "zeta", loop="open", ax=axes[0])
plotting.plot_sensitivity(result, ax=axes[1])
plt.show()
