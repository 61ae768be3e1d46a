"""The result of :func:`avar.noise_reports`: :class:`NoiseReports`, several logs of one sensor.

Holds numbers only: every log's :class:`~avar.fit.report.result.NoiseReport`, the
pooled report, the level-by-level test of agreement, the logs found in disagreement,
the spread of every term between logs, the bias-versus-temperature slopes and the
warnings. ``plot()`` overlays the logs' Allan deviations (:mod:`avar.plotting.compare`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import pandas as pd

from avar._escape import html_text, terminal
from avar.fit.report.result import NoiseReport
from avar.stability.allan.results import format_frequency

__all__ = ["NoiseReports"]

IEEE = ("QN", "WN", "FN", "RW", "DR")


def _number(value: Any) -> str:
    return "-" if value is None or value is pd.NA or value != value else f"{value:.4g}"


@dataclass(frozen=True, eq=False)
class NoiseReports:
    """Noise reports of several logs of one sensor, their pooled terms and whether they agree.

    Build it with :func:`avar.noise_reports`.

    Attributes
    ----------
    names : tuple of str
        The logs' labels, in order.
    reports : tuple of NoiseReport
        Every log's own report.
    pooled : NoiseReport
        The report of the logs' pooled Allan variance (:mod:`avar.fit.report.sessions.pooling`).
    agreement : DataFrame
        ``Channel, Tau (s), m, Statistic, Dof, P-value``: Bartlett's test of the logs' Allan
        variances at every common level (:mod:`avar.fit.report.sessions.agreement`).
    disagreements : tuple of Disagreement
        The logs found in disagreement: log, channel, term, tau, ratio, p-value.
    spread : DataFrame
        ``Channel, Term, Process, Unit, Logs, Min, Max, Max/min, Excess SD (%), Q, P-value``: every
        IEEE term present in at least two logs (SI values).
    temperature : DataFrame
        ``Log, Column, Low (degC), High (degC), Channel, Slope, SE, Unit, Windows``: the bias-versus-temperature
        slopes of the logs with a temperature column (empty without).
    false_alarm : float
        Family-wise false-alarm rate of the test (Bonferroni over :attr:`n_tests` levels).
    warnings : tuple of str
        The disagreements, the temperature drifts, and every log's and the pooled report's own warnings.
    """

    names: tuple[str, ...]
    reports: tuple[NoiseReport, ...]
    pooled: NoiseReport
    agreement: pd.DataFrame
    disagreements: tuple[Any, ...]
    spread: pd.DataFrame
    temperature: pd.DataFrame
    false_alarm: float
    warnings: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        for name in ("names", "reports", "disagreements", "warnings"):
            object.__setattr__(self, name, tuple(getattr(self, name)))
        for name in ("agreement", "spread", "temperature"):
            object.__setattr__(self, name, getattr(self, name).copy())

    @property
    def agree(self) -> bool:
        """Whether no log disagrees with the others (at the family-wise rate :attr:`false_alarm`)."""
        return not self.disagreements

    @property
    def n_tests(self) -> int:
        """Number of level tests (every common level of every channel)."""
        return len(self.agreement)

    @property
    def disagreeing(self) -> tuple[str, ...]:
        """The logs named in a disagreement, in log order."""
        named = {d.log for d in self.disagreements}
        return tuple(name for name in self.names if name in named)

    @property
    def table(self) -> pd.DataFrame:
        """Every row of the pooled report and of each log's, a ``Log`` column first (``"pooled"``, then the logs)."""
        frames = [self.pooled.table.assign(Log="pooled")]
        frames += [report.table.assign(Log=name) for name, report in zip(self.names, self.reports)]
        table = pd.concat(frames, ignore_index=True)
        return table[["Log", *[c for c in table.columns if c != "Log"]]]

    def summary(self) -> pd.DataFrame:
        """One row per channel and IEEE term: the pooled value and interval (SI), each log's value (<NA> when
        the log only bounds the term or lacks it), the ratio max/min and the excess between-log SD (%)."""
        pooled = self.pooled.table
        rows = pooled[pooled["Process"].isin(IEEE) & pooled["Status"].isin(["present", "bound"])]
        out = rows[["Channel", "Term", "Process", "Status", "Value", "Lower", "Upper", "Unit"]].rename(
            columns={"Value": "Pooled", "Status": "Pooled status"}).reset_index(drop=True)
        for name, report in zip(self.names, self.reports):
            table = report.table
            present = table[table["Status"] == "present"].set_index(["Channel", "Process"])["Value"]
            out[name] = [present.get((c, p), pd.NA) for c, p in zip(out["Channel"], out["Process"])]
            out[name] = out[name].astype("Float64")
        spread = self.spread.set_index(["Channel", "Process"])
        for column in ("Max/min", "Excess SD (%)"):
            values = [spread[column].get((c, p), pd.NA) for c, p in zip(out["Channel"], out["Process"])]
            out[column] = pd.array(values, dtype="Float64")
        return out

    def plot(self, **kwargs: Any):
        """The Allan deviation of every channel of every log, overlaid (:func:`avar.plotting.compare.plot_compare`)."""
        from avar.plotting import plot_compare

        curves, labels = [], []
        for name, report in zip(self.names, self.reports):
            for channel in report.channels:
                curves.append(report.avs[channel])
                labels.append(f"{name}: {channel}")
        return plot_compare(curves, labels=labels, **kwargs)

    def describe(self) -> str:
        return (f"Noise reports of {len(self.names)} logs of one sensor ({', '.join(map(terminal, self.names))}): "
                f"pooled N = {self.pooled.n_samples} at {format_frequency(self.pooled.rate)}")

    def verdict(self) -> str:
        """One line: whether the logs agree, by which test and at which false-alarm rate."""
        test = (f"Bartlett's test of the Allan variances at {self.n_tests} levels, family-wise false-alarm rate "
                f"{100 * self.false_alarm:g} % (Bonferroni)")
        if self.agree:
            smallest = float(self.agreement["P-value"].min()) if self.n_tests else 1.0
            return f"The logs agree ({test}; smallest p = {smallest:.2g})"
        return f"The logs disagree: {', '.join(map(terminal, self.disagreeing))} ({test})"

    def log_lines(self) -> list[str]:
        """One line per log: samples, rate, and agrees / the channels and terms where it disagrees."""
        lines = []
        for name, report in zip(self.names, self.reports):
            own = [d for d in self.disagreements if d.log == name]
            state = ("disagrees in " + "; ".join(f"{terminal(d.channel)} ({d.term}, AV x {d.ratio:.3g} at "
                                                 f"tau = {d.tau:.3g} s)" for d in own)) if own else "agrees"
            lines.append(f"  {terminal(name)}: N = {report.n_samples} at {format_frequency(report.rate)}; {state}")
        return lines

    def text(self, warnings: bool = True) -> str:
        """The printed report: the verdict, the pooled terms, one line per log, the spread, the slopes and
        (``warnings``) the warnings."""
        lines = [self.describe(), self.verdict(), "", "Pooled terms:", str(self.pooled), "", "Per log:",
                 *self.log_lines()]
        if len(self.spread):
            lines += ["", "Spread between logs (terms present in >= 2 logs; excess SD: beyond sampling):"]
            for _, row in self.spread.iterrows():
                lines.append(f"  {terminal(row['Channel'])} {row['Term']:<26} max/min {row['Max/min']:.3g}, "
                             f"excess SD {row['Excess SD (%)']:.3g} % ({row['Logs']} logs, {row['Unit']})")
        if len(self.temperature):
            lines += ["", "Bias versus temperature (least squares of window means):"]
            for _, row in self.temperature.iterrows():
                lines.append(f"  {terminal(row['Log'])} {terminal(row['Channel'])}: {_number(row['Slope'])} "
                             f"+/- {_number(row['SE'])} {row['Unit']} ({terminal(row['Column'])} "
                             f"{row['Low (degC)']:.4g} .. {row['High (degC)']:.4g} degC)")
        if warnings and self.warnings:
            lines += ["", *(f"warning: {terminal(w)}" for w in self.warnings)]
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.text()

    def __repr__(self) -> str:
        return f"<NoiseReports {self.describe()}; {'agree' if self.agree else 'disagree'}>"

    def _repr_html_(self) -> str:
        return (f"<p>{html_text(self.describe())}</p><p>{html_text(self.verdict())}</p>"
                + self.summary().to_html(index=False))
