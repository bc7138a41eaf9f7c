"""``rockyade assess --report DIR``: a page to attach, rendered in headless Chromium.

The tuff wall with its roof at the illustrative NTC site, its dynamics under the shipped selection of
seven records (``examples/site_selection``, three stripes): the page loads every figure in the browser,
and every number of its tables, the check table first, is the one of ``assess.json``. The Markdown twin
links its figures beside it; the set is replaced as a whole (an interrupted write leaves the previous
report whole) and a folder holding anything else is refused.
"""

from __future__ import annotations

import json
import re
from html import escape
from pathlib import Path
from typing import Any

import pytest

from rockyade.assess.report_model import lookup
from rockyade.cli import main
from rockyade.motion.selection_set import sha256
from rockyade.studies import assess_report

from .conftest import EXAMPLES
from .headless_browser import Browser

SITE = ["--ag", "0.2g", "--f0", "2.4", "--tc-star", "0.3", "--soil", "B"]
LC1 = ["--knowledge-level", "LC1"]
DYNAMIC = ["--records", str(EXAMPLES / "site_selection"), "--load-factors", "0.5,1,2", "--no-extend", "--quiet"]
WALL = str(EXAMPLES / "tuff_wall_roof.toml")

#: What the page is asked: its images (loaded or not), and every cell that holds a number of assess.json.
PAGE_SCRIPT = """
JSON.stringify({
  images: [...document.images].map(i => ({alt: i.alt, complete: i.complete, width: i.naturalWidth,
                                          src: i.getAttribute('src').slice(0, 22)})),
  cells: [...document.querySelectorAll('td[data-key]')].map(c => [c.dataset.key, c.dataset.value, c.textContent]),
  checks: [...document.querySelectorAll('table#checks tbody tr')].map(r => [...r.cells].map(c => c.textContent)),
  external: [...document.querySelectorAll('script, link, iframe, object, embed')].length,
  title: document.title,
})
"""


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(the assessment's --out, its --report): the wall's check and its dynamics, written once."""
    root = tmp_path_factory.mktemp("report")
    out, page = root / "out", root / "page"
    code = main(["assess", WALL, *LC1, *SITE, *DYNAMIC, "--out", str(out), "--report", str(page)])
    assert code == 0
    return out, page


def _digits(text: str) -> int:
    """Significant digits of a number as written (``0.1458`` 4, ``1.2`` 2, ``1773`` 4, ``2e-05`` 1)."""
    mantissa = re.split("[eE]", text)[0].lstrip("-").replace(".", "").lstrip("0")
    return max(len(mantissa), 1)


@pytest.mark.slow
def test_the_page_loads_every_figure_in_chromium_and_shows_the_numbers_of_assess_json(report, tmp_path):
    out, page = report
    data = json.loads((out / "assess.json").read_text())
    with Browser(tmp_path / "profile") as browser:
        browser.open(page / "report.html")
        seen: dict[str, Any] = json.loads(browser.evaluate(PAGE_SCRIPT))
        shot = browser.screenshot(tmp_path / "report.png")
    # every figure the page names is there and decoded by the browser (naturalWidth > 0), embedded
    names = ["spectrum.png", "mechanism.png", "check.png", "fragility.png", "selection.png"]
    assert len(seen["images"]) == len(names)
    for image in seen["images"]:
        assert image["complete"] and image["width"] > 100, image["alt"]
        assert image["src"] == "data:image/png;base64,"
    assert seen["external"] == 0 and "NOT VERIFIED" in seen["title"]
    assert shot.stat().st_size > 50_000  # the page drawn, figures and all
    # every number shown is assess.json's: its key and value there, and its text that value rounded
    assert len(seen["cells"]) > 60
    for key, value, text in seen["cells"]:
        expected = lookup(data, key)
        if value == "":
            assert expected is None and text == "-", key
            continue
        assert float(value) == expected, key
        decimals = len(text.split(".")[1]) if "." in text and "e" not in text else 0
        assert text in (f"{expected:.{_digits(text)}g}", f"{expected:.{decimals}f}"), (key, text, expected)
    # the check table, row by row, against the checks of assess.json
    assert len(seen["checks"]) == len(data["checks"]) == 2
    for row, check in zip(seen["checks"], data["checks"], strict=True):
        name, inequality, capacity, demand, unit, ratio, ag, verdict = row
        assert (name, inequality, unit, verdict) == (
            check["name"],
            check["inequality"],
            check["unit"],
            check["verdict"],
        )
        assert float(capacity) == pytest.approx(check["capacity"], rel=5e-4)
        assert float(demand) == pytest.approx(check["demand"], rel=5e-4)
        assert float(ratio) == pytest.approx(check["capacity_over_demand"], rel=5e-3)
        assert float(ag) == pytest.approx(check["ag_capacity_g"], rel=5e-4)
    assert data["checks"][1]["name"] == "nonlinear, ground level" and "T_SLV_s" in data["checks"][1]["terms"]


def test_the_page_holds_inputs_clauses_checks_not_made_dynamics_and_version(report):
    out, page = report
    data = json.loads((out / "assess.json").read_text())
    html = (page / "report.html").read_text()
    # self-contained: nothing loaded from elsewhere, no script; its policy forbids any
    assert "<script" not in html and "<link" not in html and "http://" not in html and "https://" not in html
    assert "Content-Security-Policy" in html and "default-src 'none'" in html
    # the inputs and their sources: the scene's SHA-256, the options given, the defaults named as such
    sha = sha256(Path(WALL))
    assert sha in html and "--knowledge-level" in html and "LC1" in html
    assert "rockyade&#x27;s default" in html and "--mechanism-damping-pct" in html
    # every check's clause and formula, and every check not made with its reason
    for check in data["checks"]:
        assert escape(check["source"]) in html
    for note in data["notes"]:
        if note.startswith("not made: "):
            assert escape(note.removeprefix("not made: ")) in html
    # the dynamic part and the record selection
    assert 'id="stripes"' in html and 'id="selection"' in html and "site_selection" in html
    # the version and the date
    assert 'id="versions"' in html and "rockyade" in html and "written (UTC)" in html


def test_the_markdown_twin_links_its_figures_beside_it(report):
    _, page = report
    md = (page / "report.md").read_text()
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", md)
    assert links == ["spectrum.png", "mechanism.png", "check.png", "fragility.png", "selection.png"]
    for link in links:
        assert (page / link).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "| nonlinear, ground level |" in md and "NOT VERIFIED" in md
    assert sorted(p.name for p in page.iterdir()) == sorted([*links, "report.md", "report.html"])


@pytest.mark.slow
def test_a_report_is_replaced_whole_or_not_at_all(tmp_path, monkeypatch, capsys):
    folder = tmp_path / "page"
    static = ["assess", WALL, *LC1, *SITE, "--static-only"]
    assert main([*static, "--report", str(folder)]) == 0
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    assert set(before) == {"spectrum.png", "mechanism.png", "check.png", "report.md", "report.html"}

    def interrupted(*args: Any, **kw: Any) -> str:
        raise KeyboardInterrupt

    monkeypatch.setattr(assess_report, "render_html", interrupted)
    assert main([*static, "--direction=-x", "--report", str(folder)]) == 130
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before  # the previous report, whole
    monkeypatch.undo()
    capsys.readouterr()
    # a folder that holds something else, another command's set or --out itself: refused before any work
    other = tmp_path / "frag"
    other.mkdir()
    (other / "fragility.json").write_text("{}")
    assert main([*static, "--report", str(other)]) == 2
    assert "--report" in capsys.readouterr().err
    assert main([*static, "--out", str(other)]) == 2
    assert "--out" in capsys.readouterr().err
    assert main([*static, "--out", str(tmp_path / "same"), "--report", str(tmp_path / "same")]) == 2
    assert "--report" in capsys.readouterr().err and not (tmp_path / "same").exists()
    assert (other / "fragility.json").read_text() == "{}"
