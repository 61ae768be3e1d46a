"""Time-error statistics and clock pairs: MTIE, TIE rms, PDEV, the three-cornered hat, GCODEV.

``deviations`` (``mtie``, ``tierms``, ``pdev``) and ``clock_pairs`` (``three_cornered_hat``,
``gcodev``). Loops: :mod:`avar._kernels.time_error`.
"""
