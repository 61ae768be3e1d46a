"""Compiled loops of the Allan variance (``avar()``), dispatched by :func:`columns.allan_variance_columns`.

``columns`` (the plain-array entry point), ``small`` (short series), ``haar`` (octave "to": the Haar
pyramid), ``pyramid``, ``sweep`` and ``far`` / ``far_steps`` (octave "mo": small levels by
moving sums by pairs, the blocks they cannot certify by a compensated sliding window, large
levels by residue class), ``levels`` (any other grid) and ``blocks`` (the block table of
compensated prefix sums every path reads).
"""
