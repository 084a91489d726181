"""The three page kinds as a person reads them (issue 32): a one-device
``calibrate --laws 2,9``, a ``diagnose`` and a ``frame`` run of one of its
calibrations on the SAC 3-story frame, each laid out by headless Chromium
in a 1400 px window.  A small script injected into a copy of each page
writes the laid-out width and every table cell's text into the DOM, which
``--dump-dom`` hands back: no cell shows more than 6 significant digits,
the page is no wider than the window, every figure has a caption, no
heading stands over nothing; the one-device page shows no Pareto front and
no robustness index, the diagnose page opens with its verdict.

Screenshots of the three pages are kept in the test's tmp folder and, when
the environment variable FVD_ARTIFACTS is set, in test-artifacts/ at the
repository's root."""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import subprocess

import numpy as np
import pytest

from conftest import CLI, REPO, SHARED, cli_env

#: the browser the Makefile's sysdeps step installs (Debian package chromium)
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
#: flags for a headless run on a closed network (no background connections)
HEADLESS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync"]
#: the window a reader has
WIDTH = 1400
#: no number on a page shows more digits than this
MAX_DIGITS = 6

pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="Chromium is not installed (make sysdeps installs it)")

#: writes what the page looks like once laid out into <pre id='fvd-measure'>
MEASURE = """<script>window.addEventListener('load', () => {
  const out = {width: document.documentElement.scrollWidth, cells: [], figures: [], empty: [],
               text: document.body.innerText, order: []};
  document.querySelectorAll('td').forEach(c => out.cells.push(c.innerText));
  document.querySelectorAll('figure').forEach(f => {
    const c = f.querySelector('figcaption'); out.figures.push(c ? c.innerText : ''); });
  document.querySelectorAll('h2, h3').forEach(h => {
    const next = h.nextElementSibling;
    if (!next || /^H[1-3]$/.test(next.tagName) && next.tagName <= h.tagName) out.empty.push(h.innerText); });
  document.querySelectorAll('h2, table, p.answer').forEach(e => out.order.push(e.tagName + ':' + e.innerText.slice(0, 160)));
  const pre = document.createElement('pre'); pre.id = 'fvd-measure'; pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});</script>"""


def significant_digits(token: str) -> int:
    """Significant digits a number as written shows: its digits without the
    sign, the exponent and leading zeros; a whole number's trailing zeros are
    not counted (123500 to 4 digits)."""
    mantissa = re.split(r"[eE]", token.lstrip("+-"))[0]
    digits = mantissa.replace(".", "").lstrip("0")
    if "." not in mantissa:
        digits = digits.rstrip("0")
    return len(digits)


def test_significant_digits_are_counted_as_a_reader_counts_them():
    assert significant_digits("1.3761150366403045") == 17 and significant_digits("0.001891") == 4
    assert significant_digits("123500") == 4 and significant_digits("-2.100e-07") == 4
    assert significant_digits("45.414") == 5 and significant_digits("0.30") == 2


def numbers_in(text: str) -> list:
    """The numbers in a cell's text (a name's digits, 'law2', count as a number too: they are short)."""
    return re.findall(r"\d+(?:\.\d+)?(?:[eE][-+]?\d+)?", text)


def run(*args, timeout=900):
    res = subprocess.run([*CLI, *map(str, args)], capture_output=True, text=True, env=cli_env(), timeout=timeout)
    assert res.returncode == 0, res.stderr[-3000:]
    return res


def quake(tmp) -> str:
    """El Centro 1940 NS from ../shared when it is there, else a synthetic record (t, a [g])."""
    elcentro = SHARED / "records" / "elcentro_1940_NS_2688pts_g_dt0.02.dat"
    if elcentro.is_file():
        return str(elcentro)
    t = np.arange(0.0, 10.0, 0.01)
    a = 0.3 * np.sin(2 * np.pi * 1.2 * t) * np.exp(-0.3 * t) * np.minimum(t, 1.0)
    path = tmp / "quake.txt"
    np.savetxt(path, np.column_stack([t, a]))
    return str(path)


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    """{kind: report.html} of a one-device calibration, its diagnosis and its frame run."""
    tmp = tmp_path_factory.mktemp("pages")
    run("rig", "--out", tmp / "rig", "--noise", "0.5", "--seed", "1")
    record = tmp / "rig" / "device_01.csv"
    run("calibrate", record, "--laws", "2,9", "--runs", "2", "--intervals", "5", "--jobs", "1", "--quiet",
        "--out", tmp / "cal")
    run("diagnose", record, "--law", "9", "--quiet", "--out", tmp / "diag")
    out = {"calibrate": tmp / "cal" / "report.html", "diagnose": tmp / "diag" / "report.html"}
    try:
        run("frame", tmp / "cal" / "params" / "device_01" / "law2.yaml", "--record", quake(tmp), "--duration", "8",
            "--quiet", "--out", tmp / "frame")
        out["frame"] = tmp / "frame" / "report.html"
    except AssertionError as exc:  # the frame verb is being reworked: its case says so, the others run
        out["frame"] = exc
    return out


def laid_out(page, tmp) -> dict:
    """The page as Chromium lays it out at WIDTH px (``MEASURE``)."""
    copy = tmp / f"measured_{page.parent.name}.html"
    copy.write_text(page.read_text().replace("</head>", MEASURE + "</head>", 1))
    dom = subprocess.run([CHROMIUM, *HEADLESS, f"--user-data-dir={tmp / 'profile'}", f"--window-size={WIDTH},3000",
                          "--dump-dom", copy.as_uri()], capture_output=True, text=True, timeout=180)
    assert dom.returncode == 0, dom.stderr[-2000:]
    found = re.search(r"<pre id=\"fvd-measure\">(.*?)</pre>", dom.stdout, re.S)
    assert found, "the measuring script did not run"
    return json.loads(html.unescape(found.group(1)))


def screenshot(page, tmp, kind: str):
    """A screenshot at WIDTH px into ``tmp`` (and test-artifacts/ with FVD_ARTIFACTS set)."""
    shot = tmp / f"page_{kind}.png"
    res = subprocess.run([CHROMIUM, *HEADLESS, f"--user-data-dir={tmp / 'profile_shot'}",
                          f"--window-size={WIDTH},3000", f"--screenshot={shot}", page.as_uri()],
                         capture_output=True, text=True, timeout=180)
    assert res.returncode == 0 and shot.is_file(), res.stderr[-2000:]
    if os.environ.get("FVD_ARTIFACTS"):
        artifacts = REPO / "test-artifacts"
        artifacts.mkdir(exist_ok=True)
        shutil.copy(shot, artifacts / shot.name)
    return shot


@pytest.mark.parametrize("kind", ["calibrate", "diagnose", "frame"])
def test_a_page_reads_at_1400_px(pages, kind, tmp_path):
    page = pages[kind]
    if isinstance(page, Exception):
        pytest.xfail(f"the frame verb failed (reworked in frames/): {str(page)[-300:]}")
    seen = laid_out(page, tmp_path)
    screenshot(page, tmp_path, kind)
    long = [c for c in seen["cells"] for x in numbers_in(c) if significant_digits(x) > MAX_DIGITS]
    assert not long, f"cells with more than {MAX_DIGITS} significant digits: {long[:5]}"
    assert seen["width"] <= WIDTH, f"the page is {seen['width']} px wide"
    assert seen["figures"] and all(len(c) > 40 for c in seen["figures"]), seen["figures"]  # says what to look at
    assert not seen["empty"], f"headings over nothing: {seen['empty']}"


def test_a_one_device_page_shows_no_series_material(pages, tmp_path):
    seen = laid_out(pages["calibrate"], tmp_path)
    text = seen["text"]
    assert "Pareto" not in text and "robustness" not in text and "beta_r" not in text
    assert "pareto.png" not in text and "of_bars.png" not in text and "dispersion_law" not in text
    # it leads with the answer: the model to use, its OF against the noise floor, then its parameters
    first = next(e for e in seen["order"] if not e.startswith("H2"))
    assert first.startswith("P:Use law 2") and "noise floor" in first
    assert "fvd-bridge export opensees" in text  # the next command


def test_a_diagnose_page_opens_with_its_verdict(pages, tmp_path):
    seen = laid_out(pages["diagnose"], tmp_path)
    assert seen["order"][0].startswith("H2:diagnosis of 9") and seen["order"][1].startswith("P:Verdict")
    tables = " ".join(e for e in seen["order"] if e.startswith("TABLE"))
    assert "law 9" in tables  # the tables name the model they show
