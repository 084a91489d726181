"""The frame page answers first (issue 41, point 3): two models with a lab's
long names, sized for a target damping and run with upper and lower bounds
(a bounds.json as a campaign writes it).

The page opens, before any table and in at most ANSWER_CHARS characters,
with the damper, the peak drift and force with the bound that governs each,
the damping achieved and whether the dampers stayed inside what was tested;
it has at most MAX_NOTES notes, each kind once; and laid out by headless
Chromium at 1400 px nothing runs past the window or out of its box, even
with names three times as long.  The terminal ends with the same answer.

The quick tests build the page from FIXTURE, the frame_summary.json of the
run below (``make_fixture``; when the summary changes, write it again:
``PYTHONPATH=tests python tests/report/test_frame_page.py``, tests/ for
conftest); the
slow ones make that run (the cheapest real one: 3-story frame, one second
of a 1 Hz pulse train, no figures; about 20 s) and check its page alike.
"""

from __future__ import annotations

import html
import json
import re
import subprocess

import numpy as np
import pytest

from conftest import CLI, REPO, cli_env
from test_pages_chromium import CHROMIUM, HEADLESS, WIDTH

#: a lab's device and models, named as labs name them
DEVICE = "ARTS-BRFD-series-2026-unit-0042-lab-B"
SPECS = ("1+series_stiffness+friction", "2+series_stiffness+friction")
#: the answer, before the first table, in at most this many characters of text
ANSWER_CHARS = 700
MAX_NOTES = 8
#: frame_summary.json of ``make_fixture``'s run
FIXTURE = REPO / "tests" / "fixtures" / "frame_page" / "frame_summary.json"
#: Chromium or a skip
chromium = pytest.mark.skipif(CHROMIUM is None, reason="Chromium is not installed (make sysdeps installs it)")

#: writes the laid-out widths into <pre id='fvd-measure'>: the page's, each table box's overflow, the
#: rightmost edge of any element
MEASURE = """<script>window.addEventListener('load', () => {
  const out = {width: document.documentElement.scrollWidth, boxes: [], right: 0, tables: 0};
  document.querySelectorAll('table').forEach(t => {
    out.tables += 1;
    const box = t.parentElement;
    out.boxes.push({overflow: Math.max(box.scrollWidth - box.clientWidth, t.scrollWidth - t.clientWidth),
                    right: t.getBoundingClientRect().right, caption: t.caption ? t.caption.innerText : ''});
  });
  document.querySelectorAll('body *').forEach(e => {
    out.right = Math.max(out.right, e.getBoundingClientRect().right); });
  const pre = document.createElement('pre'); pre.id = 'fvd-measure'; pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});</script>"""


def frame(*args):
    res = subprocess.run([*CLI, "frame", *map(str, args)], capture_output=True, text=True, env=cli_env(), timeout=900)
    assert res.returncode == 0, res.stderr[-3000:]
    return res


def make_fixture(root) -> tuple:
    """The run: calibrations of DEVICE with SPECS, a bounds.json as a campaign
    writes it (lambda 0.82 and 1.18 on the force at 300 mm/s), the frame run
    with --target-damping 0.2 --property-bounds; (its folder, its stdout)."""
    from fvd_bridge import calibrate
    from fvd_bridge.campaign.acceptance import Acceptance, design_motion
    from fvd_bridge.campaign.property_bounds import FORCE, design_forces
    from fvd_bridge.rig import VirtualDamper, Noise, paper, simulate

    rec = simulate(VirtualDamper(C=44.0, alpha=0.3, name=DEVICE), paper(cycles=3), Noise(force=1.0, displacement=0.005),
                   seed=0)
    design = {"velocity": 300.0, "amplitude": 20.0, "dt": 0.002, "cycles": 3}
    motion = design_motion(Acceptance(velocity=design["velocity"], cycles=design["cycles"]), design["amplitude"],
                           design["dt"])
    models = {}
    for spec in SPECS:
        cal = calibrate(rec, spec, seed=0, pop=8, gens=20, intervals=0)
        cal.save(str(root / "cal" / "params" / DEVICE / f"law{spec}.yaml"))
        nominal = 1.02 * float(design_forces(cal.model, cal.values, motion)[0])  # the series' mean, near this device
        models[spec] = {"nominal_device": DEVICE, "rows": [{"quantity": FORCE, "unit": "kN", "nominal": nominal,
                                                             "lambda_min": 0.82, "lambda_max": 1.18}]}
    (root / "bounds.json").write_text(json.dumps({"schema_version": 1, **design, "models": models}))
    t = np.arange(0.0, 4.0, 0.01)
    a = 0.3 * np.sin(2 * np.pi * 1.0 * t) * np.sin(np.pi * t / 4.0)
    (root / "quake.txt").write_text("\n".join(f"{x:.3f} {y:.6f}" for x, y in zip(t, a)))
    out = root / "fr"
    res = frame(root / "cal", "--record", root / "quake.txt", "--duration", "1", "--target-damping", "0.2",
                "--property-bounds", root / "bounds.json", "--no-figures", "--quiet", "--out", out)
    return out, res.stdout


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """(report.html, frame_summary.json, stdout) of ``make_fixture``'s run."""
    out, stdout = make_fixture(tmp_path_factory.mktemp("frame_page"))
    return (out / "report.html").read_text(), json.loads((out / "frame_summary.json").read_text()), stdout


def stored_page(folder, summary: dict) -> str:
    """The page ``fvd-bridge report`` builds of a folder holding ``summary`` as its frame_summary.json."""
    from fvd_bridge.report.page import build_report

    folder.mkdir(exist_ok=True)
    (folder / "frame_summary.json").write_text(json.dumps(summary))
    return open(build_report(str(folder))).read()


@pytest.fixture
def stored(tmp_path):
    """(report.html, frame_summary.json) from FIXTURE."""
    summary = json.loads(FIXTURE.read_text())
    return stored_page(tmp_path / "fr", summary), summary


def text_before_first_table(page: str) -> str:
    """The text a reader meets before the first table: the body's, tags and styles left out, spaces collapsed."""
    body = page[page.index("<body"):]
    head = re.sub(r"<(style|script)\b.*?</\1>", "", body[:body.index("<table")], flags=re.S)
    return re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", " ", head))).strip()


def check_answer(page: str, summary: dict) -> None:
    """(a): before the first table, in at most ANSWER_CHARS characters: the
    damper (model, device, factor, each story's force), the drift and the
    force with the bound governing each, the damping achieved, the tested range."""
    from fvd_bridge.report.numbers import rounded, share

    before = text_before_first_table(page)
    assert len(before) <= ANSWER_CHARS, f"{len(before)} characters before the first table: {before}"
    pick = summary["choice"]["shown"]
    env = summary["bounds"]["envelope"][pick]
    nominal = next(c for c in summary["cases"] if c["model"] == pick and c["bound"] == "nominal")
    assert f"law {pick}" in before and f"1 per story: {DEVICE} x{rounded(nominal['force_factor'], digits=3)}" in before
    assert "/".join(rounded(s["force_kN"], digits=3) for s in nominal["design"]) + " kN at" in before
    drift, force = env["drift"], env["force"]
    names = {"upper": "upper bound", "lower": "lower bound", "nominal": "nominal"}
    assert f"{rounded(drift['envelope'], digits=3)}% ({names[drift['governing']]} governs" in before
    assert f"{rounded(force['envelope'], digits=3)} kN per damper ({names[force['governing']]} governs" in before
    assert f"{share(nominal['supplemental_damping']['achieved'], 3)} of critical achieved for the 20% target" in before
    beyond = any(b["against"] == "tested" for c in summary["cases"] for b in c.get("beyond") or [])
    assert ("Beyond what was tested" if beyond else "Inside what was tested") in before


def check_notes(page: str) -> None:
    """(b): at most MAX_NOTES notes, each kind once, each marked on the cases it concerns."""
    notes = [html.unescape(n) for n in
             re.findall(r"<li>(.*?)</li>", page[page.index("<ol class='notes'>"):].split("</ol>")[0])]
    assert 0 < len(notes) <= MAX_NOTES and len(set(notes)) == len(notes), notes
    # no two notes read alike once their numbers and the cases they name are left out
    kinds = [re.sub(r"\d+(\.\d+)?", "#", n.split(" (")[0]) for n in notes]
    assert len(set(kinds)) == len(kinds), notes
    assert sum("an extrapolation" in n and "frequency" in n for n in notes) <= 1
    marks = re.findall(r"<td>((?:\[\d+\] ?)+)</td>", page)
    assert {int(k) for m in marks for k in re.findall(r"\d+", m)} == set(range(1, len(notes) + 1))


def check_width(page: str, tmp) -> None:
    """(c): laid out by Chromium at WIDTH px, no table wider than its box or the window, no element past it."""
    copy = tmp / "measured.html"
    copy.write_text(page.replace("</head>", MEASURE + "</head>", 1))
    dom = subprocess.run([CHROMIUM, *HEADLESS, f"--user-data-dir={tmp / 'profile'}", f"--window-size={WIDTH},1800",
                          "--virtual-time-budget=2000", "--dump-dom", copy.as_uri()],
                         capture_output=True, text=True, timeout=180)
    assert dom.returncode == 0, dom.stderr[-2000:]
    found = re.search(r"<pre id=\"fvd-measure\">(.*?)</pre>", dom.stdout, re.S)
    assert found, "the measuring script did not run"
    seen = json.loads(html.unescape(found.group(1)))
    assert seen["tables"] >= 3  # the dampers per story, the damping, the response
    assert seen["width"] <= WIDTH, f"the page is {seen['width']} px wide"
    wide = [b for b in seen["boxes"] if b["overflow"] > 0 or b["right"] > WIDTH]
    assert not wide, f"tables wider than their box or the window: {wide}"
    assert seen["right"] <= WIDTH, f"an element reaches {seen['right']} px"


def longer(summary: dict, times: int = 3) -> dict:
    """``summary`` with its device and model names ``times`` as long (a name with no space to break at)."""
    text = json.dumps(summary)
    for spec in SPECS:
        text = text.replace(spec, "+".join([spec] * times))
    return json.loads(text.replace(DEVICE, "-".join([DEVICE] * times)))


def test_the_page_opens_with_the_answer(stored):
    check_answer(*stored)


def test_each_kind_of_note_appears_once(stored):
    check_notes(stored[0])


def test_an_older_summary_opens_with_its_verdict(stored, tmp_path):
    """A frame_summary.json written before the answer (no 'answer', 'notes', 'choice', cases' 'beyond'):
    `fvd-bridge report` still builds its page, opening with the verdict, a note per distinct text."""
    summary = {k: v for k, v in stored[1].items() if k not in ("answer", "notes", "choice")}
    summary["cases"] = [{k: v for k, v in c.items() if k not in ("beyond", "short")} for c in summary["cases"]]
    page = stored_page(tmp_path / "old", summary)
    assert "class='answer'" not in page and "the verdict, point by point" not in page
    first = page.index("<ul class='verdict'>")
    assert first < page.index("<table") and html.escape(summary["verdict_lines"][0]) in page[first:]
    notes = re.findall(r"<li>(.*?)</li>", page[page.index("<ol class='notes'>"):].split("</ol>")[0])
    assert len(notes) == len({n for c in summary["cases"] for n in c["exceeded"]} | {
        c["note"] for c in summary["cases"] if c["model"] and c["note"] and not c["exact"]})


@chromium
def test_nothing_runs_past_the_page_at_1400_px(stored, tmp_path):
    check_width(stored[0], tmp_path)
    # names three times as long (and device names that differ only in their middle) wrap, still inside
    summary = longer(stored[1])
    devices = iter(("A", "B", "C"))
    for case in summary["cases"]:
        if case["model"] and case["bound"] == "upper":
            case["device"] = case["device"].replace("0042", f"0042-{next(devices, 'D') * 40}", 1)
    check_width(stored_page(tmp_path / "long", summary), tmp_path)


@pytest.mark.slow
def test_a_real_run_answers_first_on_the_page_and_in_the_terminal(run, tmp_path):
    page, summary, stdout = run
    check_answer(page, summary)
    check_notes(page)
    if CHROMIUM is not None:
        check_width(page, tmp_path)
    answer = "\n".join(["answer:", *[f"  {line}" for line in summary["answer"]]])
    assert answer + "\n\nwrote " in stdout  # the terminal ends with the page's answer


if __name__ == "__main__":  # PYTHONPATH=tests python tests/report/test_frame_page.py: FIXTURE again
    import shutil
    import tempfile
    from pathlib import Path

    folder, _ = make_fixture(Path(tempfile.mkdtemp()))
    FIXTURE.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(folder / "frame_summary.json", FIXTURE)
    print(f"wrote {FIXTURE}")
