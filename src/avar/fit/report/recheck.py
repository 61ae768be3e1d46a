"""The self-consistency of a noise report: :func:`recheck`, its model simulated and fitted again.

A report says "N = 2.1e-4 rad/s/sqrt(Hz), 95 % interval [2.0e-4, 2.2e-4]". Whether the
fit and its intervals can be trusted for *this* sensor's model and record length is
answered by simulation: R logs of the same length and rate are drawn from the fitted
model itself (:func:`avar.simulate_log`, every present term of every channel), each is
reported again with the same options, and for every term of the original report:

* the **ratio** recovered / fitted of every replicate where the term is resolved
  (``present``): its median should be near 1 (a median off 1 is the estimator's bias at
  this model and length);
* the **coverage**: the share of the R replicates whose interval holds the fitted value,
  which plays the truth here. A term the replicate only bounds covers when the fitted
  value is under the bound; a term the replicate rejects (``absent``) does not cover.
  For a calibrated report it is near the confidence (0.95), within the binomial
  spread sqrt(0.95 * 0.05 / R) (0.05 at R = 20).

The shaped terms are matched by their number (``AR1_1`` to ``AR1_1``): a replicate that
finds the Gauss-Markov terms in another order compares unlike with unlike, which shows
as a wide ratio. The replicates use the report's confidence and estimator type and the
octave grid of taus; the robust estimator is not repeated.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from avar._validation import check_count, check_seed
from avar.fit.report.noise_report import noise_report
from avar.fit.report.simulate import IEEE, channel_terms, simulate_channels

__all__ = ["Recheck", "recheck", "RECHECK_COLUMNS"]

#: Columns of :attr:`Recheck.table`.
RECHECK_COLUMNS = ["Channel", "Sensor", "Term", "Process", "Fitted", "Unit", "Replicates", "Resolved",
                   "Median ratio", "Ratio 5%", "Ratio 95%", "Coverage"]
#: Columns of :attr:`Recheck.values`.
VALUE_COLUMNS = ["Replicate", "Channel", "Process", "Status", "Value", "Lower", "Upper", "Ratio", "Covered"]


def _is_term(process: str) -> bool:
    head = process.split(".")[0]
    return process in IEEE or head.startswith(("AR1_", "SIN_"))


@dataclass(frozen=True, eq=False)
class Recheck:
    """The report's model simulated and fitted again; build it with :meth:`NoiseReport.recheck`.

    Attributes
    ----------
    name : str
        The report's name.
    replicates : int
        Number of simulated logs R.
    n_samples : int
        Samples per channel of every simulated log (the report's).
    rate : float
        Their sampling rate (Hz, the report's).
    confidence : float
        Confidence level of the intervals whose coverage is counted.
    table : DataFrame
        One row per channel and term of the report: ``Channel, Sensor, Term, Process, Fitted`` (the
        report's value), ``Unit``, ``Replicates``, ``Resolved`` (replicates where the term is present),
        ``Median ratio``, ``Ratio 5%``, ``Ratio 95%`` (recovered / fitted over the resolved
        replicates) and ``Coverage`` (share of the replicates whose interval holds the fitted value).
    values : DataFrame
        Every replicate's term: ``Replicate, Channel, Process, Status, Value, Lower, Upper, Ratio, Covered``.
    """

    name: str
    replicates: int
    n_samples: int
    rate: float
    confidence: float
    table: pd.DataFrame
    values: pd.DataFrame

    def summary(self) -> pd.DataFrame:
        """The terms pooled over the axes of each sensor type: ``Sensor, Process, Axes, Draws`` (axes times
        replicates), ``Median ratio`` and ``Coverage`` (pooled over every draw)."""
        sensors = self.table.set_index("Channel")["Sensor"].to_dict()
        values = self.values.assign(Sensor=self.values["Channel"].map(sensors))
        rows = []
        for (sensor, process), group in values.groupby(["Sensor", "Process"], sort=False):
            ratios = group["Ratio"].dropna().to_numpy(dtype=np.float64)
            rows.append({"Sensor": sensor, "Process": process, "Axes": group["Channel"].nunique(),
                         "Draws": len(group), "Median ratio": float(np.median(ratios)) if ratios.size else np.nan,
                         "Coverage": float(group["Covered"].mean())})
        return pd.DataFrame(rows, columns=["Sensor", "Process", "Axes", "Draws", "Median ratio", "Coverage"])

    def describe(self) -> str:
        hours = self.n_samples / self.rate / 3600.0
        return (f"Recheck of {self.name}: {self.replicates} log(s) of {self.n_samples} samples at {self.rate:.6g} Hz "
                f"({hours:.3g} h) simulated from the fitted model and reported again; median ratio recovered / "
                f"fitted and coverage of the {100 * self.confidence:g}% intervals")

    def __str__(self) -> str:
        from avar._escape import terminal

        shown = self.table.drop(columns=["Sensor", "Process", "Replicates"]).copy()
        shown["Channel"] = shown["Channel"].map(terminal)
        return self.describe() + "\n" + shown.to_string(index=False, float_format="{:.4g}".format)

    def __repr__(self) -> str:
        return f"<Recheck {self.describe()}>"


def _compare(fitted: float, row: dict[str, Any] | None) -> tuple[str, float, float, float, float, bool]:
    """(status, value, lower, upper, ratio, covered) of one replicate's term against the fitted value."""
    if row is None:
        return "absent", math.nan, math.nan, math.nan, math.nan, False
    status = row["Status"]
    value, lower, upper = (math.nan if pd.isna(row[k]) else float(row[k]) for k in ("Value", "Lower", "Upper"))
    if status == "present":
        return status, value, lower, upper, value / fitted, bool(lower <= fitted <= upper)
    if status == "bound":
        return status, value, lower, upper, math.nan, bool(fitted <= upper)
    return status, value, lower, upper, math.nan, False


def recheck(report: Any, replicates: int = 20, seed: Any = None, progress: bool | None = None,
            fit: Any = None) -> Recheck:
    """Simulate ``replicates`` logs from the report's fitted model, report each again, compare (module docstring).

    Parameters
    ----------
    report : NoiseReport
        The report to recheck (:func:`avar.noise_report`).
    replicates : int
        Number of simulated logs R, >= 1 (20 gives the coverage to about +-0.05).
    seed : None, int or numpy.random.SeedSequence
        Random seed of the simulations, for a reproducible recheck.
    progress : bool, optional
        A progress bar (tqdm) on stderr; default: when stderr is a terminal.
    fit : callable, optional
        The report function, ``fit(recording, confidence=..., type=...)`` (default :func:`avar.noise_report`).

    Returns
    -------
    Recheck
        ``table`` per channel and term, ``values`` per replicate, ``summary()`` pooled over the axes.

    Examples
    --------
    >>> import avar
    >>> x = avar.WN.from_continuous(1e-3, 100.0).simulate(20_000, seed=1)
    >>> check = avar.recheck(avar.noise_report(x, gyro_units="rad/s", rate=100.0), 3, seed=2)
    >>> row = check.table.set_index("Process").loc["WN"]
    >>> int(row["Resolved"]), bool(abs(row["Median ratio"] - 1) < 0.05)
    (3, True)
    """
    replicates = check_count(replicates, "replicates")
    fit = noise_report if fit is None else fit
    source = channel_terms(report)
    channels, rate = source.channels, source.rate
    table = report.table
    fitted = table[(table["Status"] == "present") & table["Process"].map(_is_term)]
    kinds = dict(zip(report.channels, report.sensor_types))
    estimator = next(iter(report.avs.values())).type
    root = check_seed(seed)
    if isinstance(root, (np.random.Generator, np.random.BitGenerator)):  # a generator: a seed drawn from it
        generator = root if isinstance(root, np.random.Generator) else np.random.Generator(root)
        root = int(generator.integers(2**63))
    streams = (root if isinstance(root, np.random.SeedSequence) else np.random.SeedSequence(root)).spawn(replicates)
    draws = range(replicates)
    if progress if progress is not None else sys.stderr.isatty():
        from tqdm import tqdm

        draws = tqdm(draws, desc="recheck", unit="log", file=sys.stderr, leave=False)
    records = []
    for replicate in draws:
        log = simulate_channels(channels, report.n_samples, rate, streams[replicate], source="recheck")
        again = fit(log.recording, confidence=report.confidence, type=estimator, name=f"recheck {replicate + 1}")
        column_of = {c.channel: c.column for c in log.channels}
        found = {(row["Channel"], row["Process"]): row for row in again.table.to_dict("records")}
        for row in fitted.to_dict("records"):
            value = float(row["Value"])
            compared = _compare(value, found.get((column_of[row["Channel"]], row["Process"])))
            records.append(dict(zip(VALUE_COLUMNS, (replicate + 1, row["Channel"], row["Process"], *compared))))
    values = pd.DataFrame(records, columns=VALUE_COLUMNS)
    rows = []
    for row in fitted.to_dict("records"):
        mine = values[(values["Channel"] == row["Channel"]) & (values["Process"] == row["Process"])]
        ratios = mine["Ratio"].dropna().to_numpy(dtype=np.float64)
        quantiles = np.quantile(ratios, [0.5, 0.05, 0.95]) if ratios.size else np.full(3, np.nan)
        rows.append({"Channel": row["Channel"], "Sensor": kinds.get(row["Channel"]) or "", "Term": row["Term"],
                     "Process": row["Process"], "Fitted": float(row["Value"]), "Unit": row["Unit"],
                     "Replicates": replicates, "Resolved": int(ratios.size), "Median ratio": quantiles[0],
                     "Ratio 5%": quantiles[1], "Ratio 95%": quantiles[2], "Coverage": float(mine["Covered"].mean())})
    return Recheck(name=str(report.name), replicates=replicates, n_samples=int(report.n_samples), rate=float(rate),
                   confidence=float(report.confidence), table=pd.DataFrame(rows, columns=RECHECK_COLUMNS),
                   values=values)
