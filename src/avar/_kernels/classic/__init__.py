"""Compiled loops of the classic deviations: ``sums`` (compensated cumulative sums), ``phase``
(the double-double detrended phase), ``levels`` (the terms of every level) and ``pyramid``
(ADEV/HDEV of frequency data at octave factors, with their noise-identification moments).
"""
