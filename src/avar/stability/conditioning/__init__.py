"""Data conditioning before any statistic: ``check`` (outliers, phase spikes and jumps, frequency
jumps, with their correction: Stable32's Check), ``resample`` (gap filling and averaging: Fill,
Average) and ``conversions`` (phase/frequency conversions and Stable32's drift models). Each
reports what it changed."""
