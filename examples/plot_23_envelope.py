"""
Handling qualities over the flight envelope
===========================================

The open-loop MIL-F-8785C Levels (worst mode) of the 747 in cruise as Mach and altitude move
away from the file's condition (each condition trimmed, the other derivatives held):
:func:`aerocontrol.aircraft.envelope_sweep`.
"""

import matplotlib.pyplot as plt
import numpy as np

from aerocontrol import aircraft

plane = aircraft.load("b747-cruise")
altitudes = np.linspace(plane.altitude - 10_000.0, plane.altitude + 10_000.0, 9)
machs = plane.mach * np.linspace(0.8, 1.2, 7)
envelope = aircraft.envelope_sweep(plane, altitudes=altitudes, machs=machs)
print("conditions per worst Level:", np.bincount(envelope.worst.ravel(), minlength=5)[1:])

figure, ax = plt.subplots(figsize=(9, 5), layout="constrained")
envelope.plot(ax=ax)
plt.show()
