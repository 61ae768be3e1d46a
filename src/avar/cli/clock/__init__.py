"""The time-and-frequency subcommands: ``avar deviation`` and ``avar clock-report``."""
