"""Compiled loops of the dynamic deviations: ``windows`` (every window's sums of one level from
prefix sums of the record's terms)."""
