"""The IMU subcommands: ``avar report`` (one log or several) and ``avar simulate``."""
