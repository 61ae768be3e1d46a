"""Spectra: the PSD with power-law slopes and its conversion to deviations (``spectrum``), and the phase
noise L(f), S_phi(f) of a carrier with the power-law conversions to S_y and the Allan deviation
(``phase_noise``)."""
