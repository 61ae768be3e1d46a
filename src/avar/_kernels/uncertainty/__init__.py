"""Compiled loops of noise identification (``noise_id``: lag-1 moments, R(n) clusters) and of Greenhall's EDF sums (``edf``)."""
