"""Power spectral density with power-law slopes, and its conversion to deviations (``spectrum``)."""
