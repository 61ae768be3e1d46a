"""Data conditioning before any statistic: phase/frequency conversions and Stable32's drift models (``conversions``)."""
