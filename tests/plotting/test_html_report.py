"""``avar report --html``: the page is written for real by the command line and rendered in headless Chromium.

Outside CI the Chromium test skips (with the reason) when Debian's ``chromium`` is not
installed; in CI (``CI=true``) a missing Chromium is a failure, not a skip.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser

import numpy as np
import pandas as pd
import pytest

import avar
from avar.plotting.html_report import report_html

RATE = 100.0
CHROMIUM = shutil.which("chromium") or ("/usr/bin/chromium" if os.path.exists("/usr/bin/chromium") else None)


def chromium() -> str:
    if CHROMIUM is None:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("CI=true but /usr/bin/chromium is missing: .ci/run installs Debian's chromium")
        pytest.skip("headless Chromium is not installed (Debian: apt-get install chromium)")
    return CHROMIUM


class Page(HTMLParser):
    """The rendered DOM: element counts, the rows of each table, and the visible text."""

    def __init__(self):
        super().__init__()
        self.tags: dict[str, int] = {}
        self.tables: dict[str, list[list[str]]] = {}
        self.text: list[str] = []
        self._table = self._row = None
        self._cell = False

    def handle_starttag(self, tag, attrs):
        self.tags[tag] = self.tags.get(tag, 0) + 1
        if tag == "table":
            self._table = dict(attrs).get("class", "")
            self.tables[self._table] = []
        elif tag == "tr" and self._table is not None:
            self._row = []
            self.tables[self._table].append(self._row)
        elif tag in ("td", "th") and self._row is not None:
            self._row.append("")
            self._cell = True

    def handle_endtag(self, tag):
        if tag in ("td", "th"):
            self._cell = False
        if tag == "table":
            self._table = self._row = None

    def handle_data(self, data):
        self.text.append(data)
        if self._cell and self._row:
            self._row[-1] += data


def write_log(path, n=30_000, seed=3):
    rng = np.random.default_rng(seed)
    values = rng.standard_normal((n, 6)) * 1e-3 + np.cumsum(rng.standard_normal((n, 6)), axis=0) * 1e-5
    frame = pd.DataFrame(values, columns=["gx", "gy", "gz", "ax", "ay", "az"])
    frame.insert(0, "time", np.arange(n) / RATE)
    frame.to_csv(path, index=False)
    return values


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "avar", *args], capture_output=True, text=True, timeout=300,
                          env=dict(os.environ, MPLBACKEND="Agg"))


def render(page, tmp_path) -> Page:
    out = subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                          "--disable-background-networking", "--disable-component-update", "--disable-sync",
                          f"--user-data-dir={tmp_path / 'chromium-profile'}", "--dump-dom", page.as_uri()],
                         capture_output=True, text=True, timeout=180)
    assert out.returncode == 0, out.stderr[-2000:]
    parsed = Page()
    parsed.feed(out.stdout)
    return parsed


def test_cli_html_report_renders_in_headless_chromium(tmp_path):
    chromium()
    log = tmp_path / "imu <b>&amp; log.csv"  # markup in the name must stay text
    write_log(log)
    page, table = tmp_path / "report.html", tmp_path / "terms.csv"
    result = run_cli("report", str(log), "--html", str(page), "--output", str(table))
    assert result.returncode == 0, result.stderr
    assert f"Wrote {page}" in result.stdout
    source = page.read_text(encoding="utf-8")
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:|file:|//)""", source)  # self-contained: nothing to fetch
    assert "<script" not in source
    dom = render(page, tmp_path)
    assert dom.tags.get("svg", 0) >= 1 and dom.tags.get("path", 0) > 20  # the report figure, inline
    assert dom.tags.get("b", 0) == 0  # the file name's "<b>" was escaped, not rendered as markup
    text = " ".join(" ".join(dom.text).split())
    assert "imu <b>&amp; log.csv" in text
    assert avar.__version__ in text and "--html" in text
    assert "100 Hz" in text and "30000 samples per channel" in text
    terms = pd.read_csv(table)
    rows = dom.tables["terms"]
    assert rows[0] == list(terms.columns)  # every column of the table, in order
    assert len(rows) == len(terms) + 1
    assert [r[0] for r in rows[1:]] == terms["Channel"].tolist()
    assert [r[2] for r in rows[1:]] == terms["Term"].tolist()
    for row, value in zip(rows[1:], terms["Value"]):
        assert (row[5] == "") if pd.isna(value) else float(row[5]) == pytest.approx(value, rel=1e-3)


def test_html_refuses_an_existing_file_without_force(tmp_path):
    log = tmp_path / "log.csv"
    write_log(log, n=3000)
    page = tmp_path / "report.html"
    page.write_text("keep me")
    result = run_cli("report", str(log), "--html", str(page))
    assert result.returncode == 2 and "--html" in result.stderr and "--force" in result.stderr
    assert page.read_text() == "keep me"
    result = run_cli("report", str(log), "--html", str(page), "--plot", str(page))
    assert result.returncode == 2 and page.read_text() == "keep me"
    assert run_cli("report", str(log), "--html", str(page), "--force").returncode == 0
    assert page.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")


def test_warnings_and_curves_are_rendered_when_the_report_has_them():
    x = avar.WN(sigma2=1e-4).simulate(3000, seed=2)
    report = avar.noise_report(x, gyro_units="rad/s", rate=RATE)

    class Extended:  # the report with the attributes being added beside this work
        def __getattr__(self, name):
            return getattr(report, name)

        warnings = ("x: 35% of samples at <full scale>",)
        curves = pd.DataFrame({"Channel": ["x", "x"], "Tau (s)": [0.01, 0.02], "Deviation": [1.5e-3, np.nan]})

    page = report_html(Extended(), figures=[])
    parsed = Page()
    parsed.feed(page)
    assert "x: 35% of samples at <full scale>" in "".join(parsed.text)
    assert parsed.tables["curves"] == [["Channel", "Tau (s)", "Deviation"], ["x", "0.01", "0.0015"], ["x", "0.02", ""]]
    plain = Page()
    plain.feed(report_html(report, figures=[]))
    assert plain.tables["curves"][0][:6] == ["Channel", "Tau (s)", "ADEV", "Lower", "Upper", "Implied ADEV"]
    assert len(plain.tables["curves"]) == len(report.curves) + 1 and "none" in "".join(plain.text)


#: Measures the page as Chromium lays it out at 1,280 px, every <details> opened, and writes the figures
#: into the DOM (read back with --dump-dom): the page's scroll width, each table's right edge and
#: overflow, and the tops of the summary table, the figure and the first <details>.
LAYOUT_SCRIPT = """<pre id="layout"></pre><script>
document.querySelectorAll("details").forEach(d => { d.open = true; });
const topOf = el => el ? Math.round(el.getBoundingClientRect().top + window.scrollY) : null;
const tables = [...document.querySelectorAll("table")].map(t => ({
  name: t.className, right: Math.round(t.getBoundingClientRect().right), overflow: t.scrollWidth - t.clientWidth}));
const svg = document.querySelector("figure svg");
document.getElementById("layout").textContent = JSON.stringify({
  viewport: window.innerWidth, scrollWidth: document.documentElement.scrollWidth, tables: tables,
  summary: topOf(document.querySelector("table.summary")), figure: topOf(document.querySelector("figure")),
  details: topOf(document.querySelector("details")),
  svgRight: svg ? Math.round(svg.getBoundingClientRect().right) : null});
</script></body>"""


def layout(page, tmp_path, width=1280) -> dict:
    """The layout figures of ``page`` in headless Chromium at ``width`` px (see LAYOUT_SCRIPT)."""
    import json

    probe = page.with_name(page.stem + "-probe.html")
    probe.write_text(page.read_text(encoding="utf-8").replace("</body>", LAYOUT_SCRIPT), encoding="utf-8")
    out = subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                          "--no-first-run", "--disable-background-networking", "--disable-component-update",
                          "--disable-sync", f"--user-data-dir={tmp_path / 'chromium-profile'}",
                          f"--window-size={width},900", "--virtual-time-budget=5000", "--dump-dom", probe.as_uri()],
                         capture_output=True, text=True, timeout=180)
    assert out.returncode == 0, out.stderr[-2000:]
    found = re.search(r'<pre id="layout">(.*?)</pre>', out.stdout, re.S)
    assert found and found.group(1), out.stdout[-2000:]
    return json.loads(found.group(1).replace("&quot;", '"').replace("&amp;", "&"))


def test_page_reads_top_down_and_fits_a_1280_px_window(tmp_path):
    chromium()
    log = tmp_path / "imu.csv"
    write_log(log)
    page, shot = tmp_path / "report.html", tmp_path / "report.png"
    page.write_text(report_html(avar.noise_report(avar.read(log)), command="avar report imu.csv --html report.html"),
                    encoding="utf-8")  # the page `avar report --html` writes (the test above runs the command)
    source = page.read_text(encoding="utf-8")
    assert "<details open" not in source  # the long tables start folded
    found = layout(page, tmp_path)
    assert found["viewport"] == 1280
    assert found["scrollWidth"] <= 1280, found  # no horizontal scrolling
    assert [t["name"] for t in found["tables"]] == ["summary", "terms", "curves"]
    for table in found["tables"]:
        assert table["right"] <= 1280 and table["overflow"] <= 0, table  # every table within the page, unfolded
    assert found["svgRight"] <= 1280
    assert found["summary"] < found["figure"] < found["details"], found  # summary, figure, then the details
    # the negative control: the same probe sees a page that is too wide
    wide = tmp_path / "wide.html"
    wide.write_text('<!DOCTYPE html><html><body><table class="summary"><tr><td style="min-width:2000px">x</td>'
                    "</tr></table></body></html>")
    assert layout(wide, tmp_path)["scrollWidth"] > 1280
    # a person's view: the screenshot at 1,280 px is written, 1,280 px wide
    out = subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                          f"--user-data-dir={tmp_path / 'chromium-profile'}", "--window-size=1280,2000",
                          f"--screenshot={shot}", page.as_uri()], capture_output=True, text=True, timeout=180)
    assert out.returncode == 0, out.stderr[-2000:]
    header = shot.read_bytes()[:24]
    assert header[:8] == b"\x89PNG\r\n\x1a\n" and int.from_bytes(header[16:20], "big") == 1280


def test_summary_table_gives_each_axis_its_terms_in_customary_units():
    x = avar.WN.from_continuous(1e-3, RATE).simulate(30_000, seed=4)
    report = avar.noise_report(pd.DataFrame({"gx": x, "ax": 3 * x[::-1]}), rate=RATE)
    parsed = Page()
    parsed.feed(report_html(report, figures=[]))
    from avar.plotting.html_report import SUMMARY_COLUMNS

    rows = parsed.tables["summary"]
    assert rows[0] == SUMMARY_COLUMNS and [r[0] for r in rows[1:]] == ["gx", "ax"]
    table = report.table.set_index(["Channel", "Process"])
    n_gyro = table.loc[("gx", "WN")]
    assert rows[1][1] == "Gyroscope"
    assert rows[1][2].startswith(f"{float(n_gyro['Customary']):.3g} deg/sqrt(h)")  # 1e-3 rad/s/sqrt(Hz) * 60 / deg
    assert f"[{float(n_gyro['Customary lower']):.3g}, {float(n_gyro['Customary upper']):.3g}]" in rows[1][2]
    assert rows[2][2].startswith(f"{float(table.loc[('ax', 'WN'), 'Customary']):.3g} m/s/sqrt(h)")
    for row, channel in zip(rows[1:], ("gx", "ax")):
        bias = table.loc[(channel, "FN")]
        if bias["Status"] == "bound":
            assert row[3].startswith(f"< {float(bias['Customary upper']):.3g} ") and row[3].endswith(bias["Note"])
        minimum = table.loc[(channel, "MIN")]
        assert f"at tau = {float(minimum['Tau (s)']):.3g} s" in row[5]
        fits = report.curves.loc[report.curves["Channel"] == channel, "Fits"]
        assert row[6] == f"fits {int(fits.sum())} of {len(fits)} levels"
