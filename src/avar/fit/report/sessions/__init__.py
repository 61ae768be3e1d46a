"""Several logs of one sensor: :func:`noise_reports`, per-log reports, pooled terms and whether the logs agree.

* :mod:`avar.fit.report.sessions.several_logs`: :func:`~avar.fit.report.sessions.several_logs.noise_reports`,
  the per-log work unit :func:`~avar.fit.report.sessions.several_logs.log_session`;
* :mod:`avar.fit.report.sessions.pooling`: the pooled Allan variance of the logs and its fit;
* :mod:`avar.fit.report.sessions.agreement`: the test of agreement (Bartlett's test per level) and the spread;
* :mod:`avar.fit.report.sessions.temperature`: bias versus temperature, the drift warning;
* :mod:`avar.fit.report.sessions.result`: :class:`~avar.fit.report.sessions.result.NoiseReports`.
"""
