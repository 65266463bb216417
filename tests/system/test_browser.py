"""The report looked at in a real browser: headless Chromium renders it at
1400 px (a laptop) and 390 px (a phone) wide; the screenshots are not blank,
the trust table starts on the first screen, and at 390 px nothing overflows
horizontally (tables scroll inside their own box, images scale).

The report is built from a synthetic campaign result (``tests/support/synthetic_report.py``,
~1 s); one slow test renders a real ``trilith report --quick``.  Skipped, with
the reason, only when no Chromium is installed (``.ci/run`` installs it).
"""
from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from trilith_xval.compare.run.provenance import collect
from trilith_xval.compare.report.html import write_report

BROWSER = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome")
                if shutil.which(n)), None)
pytestmark = pytest.mark.skipif(
    BROWSER is None, reason="no Chromium on PATH (Debian: apt-get install chromium; .ci/run "
                            "installs it when apt is available)")

# Headless, no network traffic of its own (the machine may be offline), fresh profile.
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars"]
PHONE, LAPTOP = (390, 844), (1400, 1000)

# Writes the page's layout numbers into the DOM, read back from --dump-dom.
PROBE = """<script>
(function () {
  var d = document.documentElement, h2 = document.querySelector('h2');
  document.body.setAttribute('data-probe', JSON.stringify({
    scrollWidth: d.scrollWidth, clientWidth: d.clientWidth, innerWidth: window.innerWidth,
    innerHeight: window.innerHeight,
    firstH2Top: h2 ? h2.getBoundingClientRect().top : null,
    firstH2: h2 ? h2.textContent : null}));
})();
</script>"""


def chromium(url: str, size: tuple[int, int], tmp_path: Path, *extra: str) -> str:
    profile = tmp_path / f"profile-{size[0]}-{len(extra)}"
    profile.mkdir(exist_ok=True)
    cmd = [BROWSER, *FLAGS, f"--user-data-dir={profile}", f"--window-size={size[0]},{size[1]}",
           *extra, url]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120, check=False,
                          cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return proc.stdout


def probe(html_path: Path, size: tuple[int, int], tmp_path: Path) -> dict:
    """Layout numbers of ``html_path`` rendered at ``size``."""
    page = tmp_path / f"probe-{size[0]}.html"
    page.write_text(html_path.read_text(encoding="utf-8").replace("</body>", PROBE + "</body>"),
                    encoding="utf-8")
    dom = chromium(page.as_uri(), size, tmp_path, "--virtual-time-budget=3000", "--dump-dom")
    match = re.search(r'data-probe="([^"]*)"', dom)
    assert match, "probe script did not run"
    return json.loads(match.group(1).replace("&quot;", '"'))


# Chromium lays a --dump-dom page out at least 500 px wide; only --screenshot
# (with virtual time, after its resize) lays it out at 390 px.  So the widths are
# drawn as bars (half a pixel per CSS px) on top of the page and read back from
# the screenshot: red = scrollWidth, blue = innerWidth, green = clientWidth.
BARS = """<div id='probe-bars' style='position:fixed;top:0;left:0;z-index:2147483647'></div>
<script>
(function () {
  function draw() {
    var d = document.documentElement, box = document.getElementById('probe-bars');
    var bars = [[d.scrollWidth, '#ff0000'], [window.innerWidth, '#0000ff'],
                [d.clientWidth, '#00ff00']];
    box.innerHTML = bars.map(function (b) {
      return "<div style='height:6px;width:" + Math.floor(b[0] / 2) + "px;background:" + b[1]
             + "'></div>"; }).join('');
  }
  draw(); addEventListener('resize', draw); addEventListener('load', draw);
  setTimeout(draw, 500);
})();
</script>"""


def widths(html_path: Path, size: tuple[int, int], tmp_path: Path) -> dict:
    """scrollWidth, innerWidth and clientWidth of the page laid out at ``size``
    (to 2 px: read off the bars of :data:`BARS`)."""
    page = tmp_path / f"bars-{size[0]}.html"
    page.write_text(html_path.read_text(encoding="utf-8").replace("</body>", BARS + "</body>"),
                    encoding="utf-8")
    png = tmp_path / f"bars-{size[0]}.png"
    chromium(page.as_uri(), size, tmp_path, "--force-device-scale-factor=1",
             "--virtual-time-budget=3000", f"--screenshot={png}")
    with Image.open(png) as im:
        px = np.asarray(im.convert("RGB"), dtype=int)

    def bar(row, channel):
        line = px[row]
        hit = (line[:, channel] > 200) & (np.delete(line, channel, axis=1).max(axis=1) < 60)
        return 2 * int(hit.sum())

    return {"scroll": bar(3, 0), "inner": bar(9, 2), "client": bar(15, 1)}


def screenshot(html_path: Path, size: tuple[int, int], tmp_path: Path) -> np.ndarray:
    png = tmp_path / f"shot-{size[0]}.png"
    chromium(html_path.as_uri(), size, tmp_path, f"--screenshot={png}")
    with Image.open(png) as im:
        return np.asarray(im.convert("RGB"), dtype=float)


def assert_not_blank(pixels: np.ndarray, size: tuple[int, int]) -> None:
    assert pixels.shape[:2] == (size[1], size[0])
    # A rendered report: text and coloured cells on white.  Blank (all white, or
    # one flat colour) has zero variance and no dark pixels.
    assert pixels.std() > 20.0
    dark = (pixels.mean(axis=2) < 100).mean()
    assert dark > 0.005, f"only {dark:.4f} of the pixels are dark: no text drawn?"


@pytest.fixture(scope="module")
def synthetic_report(tmp_path_factory):
    from tests.support.synthetic_report import synthetic_result

    out = tmp_path_factory.mktemp("report")
    result = synthetic_result()
    write_report(result, out, collect(quick=True, backends=result.versions))
    return out / "index.html"


@pytest.mark.parametrize("size", [LAPTOP, PHONE], ids=["1400px", "390px"])
def test_screenshot_is_not_blank(synthetic_report, size, tmp_path):
    assert_not_blank(screenshot(synthetic_report, size, tmp_path), size)


def test_trust_table_on_the_first_screen(synthetic_report, tmp_path):
    p = probe(synthetic_report, LAPTOP, tmp_path)
    assert p["innerWidth"] == LAPTOP[0]
    assert p["firstH2"] == "Trust table"
    assert 0 < p["firstH2Top"] < 0.5 * p["innerHeight"]


def test_no_horizontal_overflow_at_phone_width(synthetic_report, tmp_path):
    w = widths(synthetic_report, PHONE, tmp_path)
    assert w["inner"] == PHONE[0], w  # the page really was laid out 390 px wide
    assert w["scroll"] <= w["client"], w


def test_the_overflow_probe_detects_overflow(tmp_path):
    """Control: a page with a 1000 px wide element does overflow at 390 px."""
    page = tmp_path / "wide.html"
    page.write_text("<!DOCTYPE html><html><head><meta name='viewport' "
                    "content='width=device-width'></head><body><h2>x</h2>"
                    "<div style='width:1000px'>wide</div></body></html>")
    w = widths(page, PHONE, tmp_path)
    assert w["inner"] == PHONE[0] and w["scroll"] > w["client"], w


@pytest.mark.slow
def test_real_quick_report_in_the_browser(tmp_path):
    """A real ``trilith report --quick`` on the two cheapest engines: the QUICK
    banner, the trust table for each engine, and the same browser checks.  The
    page's layout does not depend on which engines fill it; DART and Drake would
    multiply the cost (their runs take 5-15x Pymunk's CPU)."""
    from trilith_xval.compare.cli.main import main

    out = tmp_path / "report"
    assert main(["report", "--quick", "--engine", "pymunk,mujoco", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["quick"] is True and summary["provenance"]["quick"] is True
    assert "--quick" in summary["provenance"]["command"]
    assert set(summary["trust"]) == set(summary["config"]["engines"])
    html = (out / "index.html").read_text(encoding="utf-8")
    assert "QUICK RUN" in html
    for size in (LAPTOP, PHONE):
        assert_not_blank(screenshot(out / "index.html", size, tmp_path), size)
    w = widths(out / "index.html", PHONE, tmp_path)
    assert w["inner"] == PHONE[0] and w["scroll"] <= w["client"], w


# Words split across lines inside table cells ("PyBulle|t", "4.4e-|4"): each word
# of each text node in a table is a DOM Range; a word laid out on one line has one
# client rectangle.  The count is drawn as a red bar (4 px per split word, plus 2 px
# that show the script ran) and read back from a screenshot, as for BARS (only a
# screenshot lays the page out at 390 px).
SPLIT_WORDS = """<div id='probe-split' style='position:fixed;top:0;left:0;z-index:2147483647'></div>
<script>
(function () {
  function count() {
    var n = 0, walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
    while (walker.nextNode()) {
      var node = walker.currentNode;
      if (!node.parentElement.closest('td,th')) continue;
      var re = /\\S+/g, m;
      while ((m = re.exec(node.data)) !== null) {
        var r = document.createRange();
        r.setStart(node, m.index); r.setEnd(node, m.index + m[0].length);
        var tops = {};
        Array.prototype.forEach.call(r.getClientRects(), function (q) {
          if (q.width > 0) tops[Math.round(q.top)] = 1; });
        if (Object.keys(tops).length > 1) n += 1;
      }
    }
    return n;
  }
  function draw() {
    document.getElementById('probe-split').innerHTML =
      "<div style='height:6px;width:" + (2 + 4 * count()) + "px;background:#ff0000'></div>";
  }
  addEventListener('load', draw); setTimeout(draw, 500);
})();
</script>"""


def split_words(html_path: Path, size: tuple[int, int], tmp_path: Path) -> int:
    """How many words in table cells are broken across lines at ``size``."""
    page = tmp_path / f"split-{size[0]}.html"
    page.write_text(html_path.read_text(encoding="utf-8").replace("</body>",
                                                                  SPLIT_WORDS + "</body>"),
                    encoding="utf-8")
    png = tmp_path / f"split-{size[0]}.png"
    chromium(page.as_uri(), size, tmp_path, "--force-device-scale-factor=1",
             "--virtual-time-budget=3000", f"--screenshot={png}")
    with Image.open(png) as im:
        line = np.asarray(im.convert("RGB"), dtype=int)[3]
    red = int(((line[:, 0] > 200) & (line[:, 1] < 60) & (line[:, 2] < 60)).sum())
    assert red >= 2, "the split-word probe did not run"
    return (red - 2) // 4


@pytest.mark.parametrize("size", [LAPTOP, PHONE], ids=["1400px", "390px"])
def test_no_word_is_split_across_lines(synthetic_report, size, tmp_path):
    """Engine names, ids, numbers with their exponent ("4.4e-4") and hyphenated
    modes ("after-impact") stay whole at laptop and phone width."""
    assert split_words(synthetic_report, size, tmp_path) == 0


def test_the_split_word_probe_detects_a_split(tmp_path):
    """Control: a 40 px column that may break anywhere splits 'PyBullet'."""
    page = tmp_path / "split.html"
    page.write_text("<!DOCTYPE html><html><head><meta name='viewport' "
                    "content='width=device-width'></head><body><table><tr>"
                    "<td style='width:40px;max-width:40px;overflow-wrap:anywhere'>PyBullet "
                    "MuJoCoMuJoCo</td></tr></table></body></html>")
    assert split_words(page, LAPTOP, tmp_path) >= 1
