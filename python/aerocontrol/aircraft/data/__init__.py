"""The shipped aircraft files (TOML), read by :func:`aerocontrol.aircraft.load`."""
