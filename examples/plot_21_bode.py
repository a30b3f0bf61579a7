"""
Bode plots of the 747
=====================

Pitch rate to elevator (longitudinal) and yaw rate to rudder (lateral): the short-period and
phugoid peaks, and the Dutch roll's.
"""

import matplotlib.pyplot as plt

from aerocontrol import aircraft, bode, plotting

plane = aircraft.load("b747-approach")
longitudinal, lateral = plane.longitudinal(), plane.lateral()
figure, axes = plt.subplots(2, 2, figsize=(11, 6), layout="constrained")
plotting.plot_bode(
    bode(longitudinal), ax=(axes[0, 0], axes[1, 0]), output=longitudinal.state_names.index("q")
)
plotting.plot_bode(
    bode(lateral),
    ax=(axes[0, 1], axes[1, 1]),
    output=lateral.state_names.index("r"),
    input=lateral.input_names.index("rudder"),
)
plt.show()
