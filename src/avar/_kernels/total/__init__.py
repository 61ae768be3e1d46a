"""Compiled loops of the total and Theo statistics: ``windows`` (detrended, reflected windows),
``blocks`` (long levels in O(N)), ``theo1`` (Theo1's long levels from FFT autocorrelations),
``theobr`` (Theo1 and OAVAR at every factor at once), ``mhtot`` (MHTOTDEV's windows) and
``mhtot_blocks`` (its long levels in O(N)), ``split`` and ``fft`` (the FFT primitives).
"""
