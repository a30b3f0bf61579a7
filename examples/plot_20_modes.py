"""
The modes and their handling qualities
======================================

The 747's longitudinal and lateral modes in the complex plane, named (short period, phugoid,
Dutch roll, roll, spiral), and their MIL-F-8785C Levels for a Class III aircraft in Flight
Phase Category C.
"""

import matplotlib.pyplot as plt

from aerocontrol import aircraft, handling, plotting

plane = aircraft.load("b747-approach")
named = {}
for axis in ("longitudinal", "lateral"):
    named.update(aircraft.classify_modes(plane.modes(axis), axis))
print(handling.assess(named, plane.aircraft_class, plane.category))

figure, axes = plt.subplots(1, 2, figsize=(11, 4.4), layout="constrained")
for ax, axis in zip(axes, ("longitudinal", "lateral"), strict=True):
    plotting.plot_modes(plane.modes(axis), ax=ax)
    ax.set_title(f"{axis} modes")
plt.show()
