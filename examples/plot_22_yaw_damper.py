"""
A yaw damper by root locus, checked against MIL-F-9490D
=======================================================

Yaw rate fed back to the rudder through a 10 rad/s actuator and a washout τs/(τs + 1), at the
gain that best damps the Dutch roll (:func:`aerocontrol.design.yaw_damper`). The root locus of
1 + kL(s) = 0 with the chosen gain marked, and the loop's margins against the requirement of
MIL-F-9490D (the values as widely quoted: the specification's table is not verified here).
"""

import matplotlib.pyplot as plt
import numpy as np

from aerocontrol import aircraft, design, plotting, root_locus

damper = design.yaw_damper(aircraft.load("b747-cruise"))
print(f"gain {damper.design.gain:.3f}, Dutch roll ζ = {damper.design.damping_ratio:.3f}")
print(damper.margins)
print(damper.check)

gains = np.r_[0.0, np.geomspace(1e-3, 10 * damper.design.gain, 600)]
locus = root_locus(damper.loop, gains)
figure, ax = plt.subplots(figsize=(8, 5.5), layout="constrained")
plotting.plot_gain_root_locus(locus, ax=ax, marked=[damper.design.gain])
ax.set_xlim(-4, 0.5)
ax.set_ylim(-2, 2)
plt.show()
