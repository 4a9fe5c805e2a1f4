"""The reproduction report's rendering and its verdict rules, on hand-made sections (no computation)."""

from __future__ import annotations

import html
import re
from datetime import UTC
from html.parser import HTMLParser

import pytest

from geardyn.paper import CLAIMS
from geardyn.paper.report import (
    SUMMARY_COLUMNS,
    VERDICTS,
    Section,
    dataset_of,
    render_html,
    render_markdown,
    write_report,
)
from geardyn.paper.settings import model_text
from geardyn.paper.table1 import TABLE1_MODEL
from geardyn.paper.verdicts import (
    VERDICT_RULES,
    count_text,
    of_claims,
    parts,
    verdict_of,
)

#: ASCII spellings of the model's parameters that the report's text must write as symbols.
ASCII_NAMES = re.compile(r"\b(xi\d|xi_\d|omega|kappa\d?|eps\d|fp)\b|omega\s*=")
#: "k of N" counts in a claim's text.
COUNTS = re.compile(r"(?<![\d.])(\d+) of (\d+)(?!\.?\d)")


class _Text(HTMLParser):
    """The visible text of a page (no tags, attributes, styles or embedded images)."""

    def __init__(self) -> None:
        super().__init__()
        self.parts: list[str] = []
        self._skip = 0

    def handle_starttag(self, tag, attrs):
        self._skip += tag in ("style", "script")

    def handle_endtag(self, tag):
        self._skip -= tag in ("style", "script")

    def handle_data(self, data):
        if not self._skip:
            self.parts.append(data)


def visible_text(page: str) -> str:
    p = _Text()
    p.feed(page)
    return re.sub(r"\s+", " ", "".join(p.parts))


def markdown_text(md: str) -> str:
    """Markdown without link and image targets (what a reader sees)."""
    return re.sub(r"\]\([^)]*\)", "]", md)


def check_report_text(text: str) -> None:
    """The wording checks every rendered report must pass."""
    assert not re.search(r"=\s*none\b", text), "a value written as '= none'"
    m = ASCII_NAMES.search(text)
    assert m is None, f"ASCII parameter name {m.group(0)!r} in the report text"


def check_verdict_wording(claims) -> None:
    """No claim's words contradict its verdict: a reproduction under a reading names a reading that holds; a
    claim reproduced at the default reading has no failing count."""
    for c in claims:
        counts = [(int(k), int(n)) for k, n in COUNTS.findall(c.computed)]
        if c.verdict == "reproduced under a reading":
            assert c.reading and c.reading in c.deciding, f"{c.id}: reproduced under a reading it does not name"
        if c.verdict == "reproduced" and counts:
            assert all(k / n >= 0.8 for k, n in counts if n), f"{c.id}: reproduced with a failing count: {c.computed}"


def _sections():
    f1 = CLAIMS["T2-1"].judge(
        "at ω = 1: chaotic over 75 % of the interval's length.",
        "contradicted",
        [
            "data/xi0_bifurcation.nc",
            "figures/xi0_bifurcation/bifurcation.png",
            "figures/xi0_bifurcation/bifurcation.png",
        ],
    )
    f2 = CLAIMS["JUMP-057"].judge(
        "within ±0.03 of ω = 0.57 for 0 of 4 backlash values (0 %).",
        "contradicted",
        ["data/response_xi0_0.08_xi1_0.05_D_0.1.nc"],
    )
    return [
        Section(
            "A", ["text"], [("figures/xi0_bifurcation/bifurcation.png", "Bifurcation diagram over ξ0, ω = 1")], [f1]
        ),
        Section("B", [], [], [f2], [["ξ0", "D"], ["0.08", "0.1"]]),
    ]


LABELS = {
    "xi0_bifurcation": "bifurcation diagram over ξ0 (ω = 1, ξ1 = 0.05, D = 1)",
    "response_xi0_0.08_xi1_0.05_D_0.1": "frequency response at ξ0 = 0.08, ξ1 = 0.05, D = 0.1",
}


def test_summary_has_paper_says_beside_we_find_and_the_verdict_and_totals_come_first(tmp_path):
    page = render_html("T", ["intro"], _sections(), tmp_path, LABELS)
    assert SUMMARY_COLUMNS == ("id", "source", "paper says", "we find", "verdict", "deciding evidence")
    header = "<tr>" + "".join(f"<th>{h}</th>" for h in SUMMARY_COLUMNS) + "</tr>"
    assert header in page
    totals = "Totals (2 claims): 0 reproduced, 0 reproduced under a reading, 2 contradicted, 0 not testable."
    assert page.index(totals) < page.index(header)
    row = re.search(r"<tr><td><a href='#T2-1'>.*?</tr>", page).group(0)
    assert "ξ0 &lt; 0.064: chaotic motion" in row and "75 % of the interval" in row and "contradicted" in row
    md = render_markdown("T", ["intro"], _sections(), LABELS)
    assert "| id | source | paper says | we find | verdict | deciding evidence |" in md
    assert md.index("Totals (2 claims)") < md.index("| id | source | paper says")
    assert f"| T2-1 | Table 2, row 1 | {CLAIMS['T2-1'].statement} |" in md


def test_evidence_is_named_by_what_it_is_and_shown_figures_link_to_their_place(tmp_path):
    (tmp_path / "figures" / "xi0_bifurcation").mkdir(parents=True)
    (tmp_path / "figures" / "xi0_bifurcation" / "bifurcation.png").write_bytes(b"\x89PNG")
    page = render_html("T", [], _sections(), tmp_path, LABELS)
    text = visible_text(page)
    assert "bifurcation diagram over ξ0 (ω = 1, ξ1 = 0.05, D = 1) (data, figure)" in text  # each path once
    assert "href='#fig-figures-xi0-bifurcation-bifurcation-png'" in page
    assert "<figure id='fig-figures-xi0-bifurcation-bifurcation-png'>" in page
    assert "href='data/response_xi0_0.08_xi1_0.05_D_0.1.nc'" in page  # data are linked, not shown
    check_report_text(text)
    check_report_text(markdown_text(render_markdown("T", [], _sections(), LABELS)))
    assert dataset_of("figures/a_b/x.png") == "a_b" and dataset_of("data/a_b.nc") == "a_b"


def test_the_text_checks_catch_what_they_are_for():
    with pytest.raises(AssertionError, match="= none"):
        check_report_text("single-sided at all three only at ω = none")
    for bad in ("Bifurcation diagram over xi0", "omega=0.525", "at xi1 = 0.05", "kappa1 = 0.2"):
        with pytest.raises(AssertionError, match="ASCII"):
            check_report_text(bad)
    check_report_text("ξ0 = 0.08, ξ1 = 0.05, ω = 0.6, κ1 = 0.2, f_p = 0.2; jumps within ±0.05: none")
    bad = CLAIMS["JUMP-057"].judge("within ±0.03 of 0.57 for 0 of 4.", "reproduced under a reading", ["x"])
    with pytest.raises(AssertionError, match="does not name"):
        check_verdict_wording([bad])
    bad.reading, bad.deciding = "φ_c1 = π", "holds under φ_c1 = π"
    check_verdict_wording([bad])


def test_verdict_kinds_and_the_combining_rules():
    assert VERDICTS == ("reproduced", "reproduced under a reading", "contradicted", "not testable")
    for n in range(1, 12):
        assert verdict_of(0 / n) == "contradicted"
        assert verdict_of(n / n) == "reproduced"
    assert verdict_of(float("nan")) == "contradicted"
    # every part of a claim is required: one part holding is not enough
    assert parts(False, False) == "contradicted" and parts(True, False) == "contradicted"
    assert parts(True, True) == "reproduced" and parts(True, True, False, False, False) == "contradicted"
    assert of_claims(["reproduced", "reproduced"]) == "reproduced"
    assert of_claims(["reproduced", "contradicted"]) == "contradicted"
    assert count_text(0, 4, "backlash values") == "0 of 4 backlash values (0 %)"
    assert count_text(1, 2, "") == "1 of 2 (50 %)"
    with pytest.raises(ValueError):
        CLAIMS["T2-1"].judge("x", "partly reproduced", [])


def test_verdict_rules_are_stated_once_in_the_report(tmp_path):
    from geardyn.paper.run import settings_section
    from geardyn.paper.settings import Settings

    sections = [settings_section(Settings.quick(), 1.0), *_sections()]
    paths = write_report(tmp_path, "T", [], sections, labels=LABELS)
    text = visible_text(paths["html"].read_text())
    for rule in VERDICT_RULES:
        assert text.count(rule) == 1
    assert "Four kinds of verdict." in text and "Ranges are judged by length." in text
    check_report_text(text)


def test_model_text_names_the_parameters_with_their_symbols():
    m = TABLE1_MODEL.replace(xi0=0.08, D=0.25)
    assert model_text(m) == "ω = 1, ξ0 = 0.08, ξ1 = 0.05, D = 0.25"
    assert model_text(m, skip=("omega",)) == "ξ0 = 0.08, ξ1 = 0.05, D = 0.25"
    assert model_text(m, only=("fp", "kappa1")) == "f_p = 0.2, κ1 = 0.2"


# --- what run a report comes from: quick or full, version, date, command line ----------------------------------
def _run_info(kind="quick"):
    from geardyn.paper.report import RunInfo
    from geardyn.paper.settings import Settings

    changes = Settings.quick().changes() if kind == "quick" else []
    return RunInfo("9.8.7", "2026-12-02T12:00:00Z", "geardyn reproduce --out r --quick", kind, changes)


def test_a_quick_report_says_so_at_the_top_with_what_was_reduced_and_labels_its_totals(tmp_path):
    run = _run_info("quick")
    page = render_html("T", ["intro"], _sections(), tmp_path, LABELS, run)
    text = visible_text(page)
    box = page.index("<div class='reduced'>")
    assert page.index("<h1>T (quick run)</h1>") < box < page.index("<p>intro</p>") < page.index("Claims and verdicts")
    assert "<title>T (quick run)</title>" in page
    banner = text[text.index("Quick run:") :]
    assert banner.startswith("Quick run: reduced grids, fewer points and shorter runs than the full reproduction")
    assert "may differ from the full run" in banner[:300]
    for change in run.changes:  # every reduced setting named, with the full run's value
        assert f"<li>{html.escape(change)}</li>" in page
    assert "points of each frequency response: 12 (full run: 91)" in run.changes
    assert (
        "Totals of this quick run (2 claims): 0 reproduced, 0 reproduced under a reading, 2 contradicted, "
        "0 not testable (may differ from the full run)."
    ) in text
    assert "Totals (2 claims)" not in text
    md = render_markdown("T", ["intro"], _sections(), LABELS, run)
    assert md.startswith("# T (quick run)\n") and md.index("> **Quick run:") < md.index("## Claims and verdicts")
    assert (
        "> - points of each frequency response: 12 (full run: 91)" in md and "Totals of this quick run (2 claims)" in md
    )
    full = render_html("T", ["intro"], _sections(), tmp_path, LABELS, _run_info("full"))
    assert "class='reduced'" not in full and "<h1>T</h1>" in full and "Totals (2 claims): " in full
    assert "quick" not in visible_text(full).replace("--quick", "")


def test_the_report_names_the_geardyn_version_the_date_and_the_command_line(tmp_path):
    import json

    run = _run_info("full")
    page = render_html("T", ["intro"], _sections(), tmp_path, LABELS, run)
    head = page[: page.index("<p>intro</p>")]
    assert "geardyn 9.8.7" in head and "2026-12-02T12:00:00Z" in head
    assert "<code>geardyn reproduce --out r --quick</code>" in head
    md = render_markdown("T", ["intro"], _sections(), LABELS, run)
    assert "*geardyn 9.8.7, run 2026-12-02T12:00:00Z: geardyn reproduce --out r --quick*" in md.split("## ")[0]
    paths = write_report(tmp_path, "T", ["intro"], _sections(), meta={"compute_s": 1.0}, labels=LABELS, run=run)
    meta = json.loads(paths["meta"].read_text())
    assert meta["run"] == {
        "version": "9.8.7",
        "date": "2026-12-02T12:00:00Z",
        "command": "geardyn reproduce --out r --quick",
        "kind": "full",
        "changes": [],
    }
    assert meta["compute_s"] == 1.0 and meta["totals"].startswith("Totals (2 claims)")


def test_run_kind_and_changes_of_the_settings():
    from dataclasses import replace

    from geardyn.paper.settings import Settings

    assert Settings().changes() == [] and Settings().run_kind() == "full"
    assert replace(Settings(), workers=7).run_kind() == "full"  # workers change the time, not the results
    assert replace(Settings.quick(), workers=2).run_kind() == "quick"
    one = Settings(transient=5)
    assert one.run_kind() == "changed" and one.changes() == [
        "transient periods of the bifurcation diagrams: 5 (full run: 300)"
    ]
    quick = Settings.quick().changes()
    assert (
        "ξ0 grid of the ξ0 bifurcation diagram: 5 points over [0.03, 0.5] (full run: 62 points over [0.02, 0.95])"
        in quick
    )
    assert "ω grid of the stability condition: 2 points (0.8, 1.6) (full run: 21 points over [0.4, 2.4])" in quick
    assert "ω interval of the continuation: [0.61, 0.63] (full run: [0.5, 0.7])" in quick


def test_run_info_records_the_version_the_date_now_and_the_command():
    from datetime import datetime

    import geardyn
    from geardyn.paper.run import PYTHON_COMMAND, run_info
    from geardyn.paper.settings import Settings

    before = datetime.now(UTC).replace(microsecond=0)
    info = run_info(Settings.quick(), "geardyn reproduce --quick")
    after = datetime.now(UTC)
    assert info.version == geardyn.__version__ and info.command == "geardyn reproduce --quick"
    assert before <= datetime.fromisoformat(info.date.replace("Z", "+00:00")) <= after
    assert info.kind == "quick" and info.changes == Settings.quick().changes()
    assert run_info(Settings()).command == PYTHON_COMMAND and not run_info(Settings()).reduced


def _table_rows(out: str) -> dict[str, list[str]]:
    """The rows of a rich table as printed: id → the text of each further column (wrapped lines joined)."""
    rows: dict[str, list[str]] = {}
    current = None
    for line in out.splitlines():
        if not line.startswith("│"):
            continue
        cells = [c.strip() for c in line.strip("│").split("│")]
        if cells[0]:
            current = cells[0]
            rows[current] = cells[1:]
        elif current is not None:
            rows[current] = [f"{a} {b}".strip() for a, b in zip(rows[current], cells[1:])]
    return rows


@pytest.mark.parametrize("width", [80, 160])
def test_terminal_summary_prints_each_claims_statement_beside_its_verdict_and_says_quick_first(monkeypatch, width):
    import io

    from rich.console import Console

    from geardyn.cli import render

    buf = io.StringIO()
    monkeypatch.setattr(render, "console", Console(file=buf, width=width, color_system=None))
    claims = [c for s in _sections() for c in s.claims]
    render.claims({"claims": claims, "paths": {"html": "r/report.html"}, "seconds": 3.0, "run": _run_info("quick")})
    out = buf.getvalue()
    flat = re.sub(r"\s+", " ", out)
    assert out.lstrip().startswith("Quick run: reduced grids")
    assert flat.index("Quick run") < flat.index("Totals of this quick run (2 claims)") < flat.index("T2-1")
    rows = _table_rows(out)
    assert list(rows) == [c.id for c in claims]
    for c in claims:  # the paper's statement, whole, on the claim's row beside its verdict
        assert rows[c.id] == [c.statement, c.verdict], rows[c.id]
    assert "geardyn 9.8.7, run 2026-12-02T12:00:00Z: geardyn reproduce --out r --quick" in flat
    assert "verdicts may differ from the full run" in flat.split("r/report.html")[-1]
    buf.truncate(0), buf.seek(0)
    render.claims({"claims": claims, "paths": {"html": "r/report.html"}, "seconds": 3.0, "run": _run_info("full")})
    assert "Quick" not in buf.getvalue() and "Totals (2 claims)" in re.sub(r"\s+", " ", buf.getvalue())


def test_totals_under_one_reading_per_table_come_first_and_count_each_group_at_one_reading(tmp_path):
    """Table 3's rows and the backlash study's claims come from one setting in the paper: under one reading for
    the group, only the claims that hold under that one reading count (here the reading two of them share)."""
    from geardyn.paper.report import Finding, Section, one_reading_text, one_reading_totals, render_markdown

    r = "ω = 1.30, D = b/(2 mm)"
    claims = [
        Finding("T3-1", "Table 3, row 1", "s", "c", "reproduced"),
        Finding("T3-2", "Table 3, row 2", "s", "c", "reproduced under a reading", reading="ω = 1.05"),
        Finding("T3-3", "Table 3, row 3", "s", "c", "reproduced under a reading", reading=r),
        Finding("BL-IMPACT", "text", "s", "c", "reproduced under a reading", reading=r),
        Finding("BL-AMP", "text", "s", "c", "contradicted"),
        Finding("FORMULA", "formula", "s", "c", "reproduced under a reading", reading="φ = π"),
    ]
    t = one_reading_totals(claims)
    assert t["groups"]["Table 3 and the backlash study"] == (r, 2, 5)
    assert t["reproduced under the group's reading"] == 3  # T3-3, BL-IMPACT, and FORMULA alone in its group
    assert t["not reproduced"] == 3 and t["reproduced"] == 0
    # a reading chosen for the whole table counts the rows that hold under it
    claims[0].table_reading, claims[0].table_holds = "best", True
    claims[1].table_reading, claims[1].table_holds = "best", True
    claims[2].table_reading, claims[2].table_holds = "best", True
    assert one_reading_totals(claims)["groups"]["Table 3 and the backlash study"] == ("best", 3, 5)
    page = render_markdown("t", [], [Section("s", claims=claims)])
    first = one_reading_text(claims)
    assert first.startswith("Totals under one reading per table or study (6 claims, 2 groups)")
    assert page.index(first) < page.index("Per claim, each under its own nearest reading")


def test_report_leftovers_times_command_digits_and_source():
    """The report's time is the one the command prints; its command line shows only what was typed; values judged
    strictly increasing print unequal; the source is stated as the text gives it (title only)."""
    from geardyn.paper.run import INTRO, settings_section
    from geardyn.paper.settings import Settings
    from geardyn.paper.verdicts import distinct_text

    text = " ".join(settings_section(Settings.quick(), 145.6, 178.3).paragraphs)
    assert "145.6 s for the studies, 178.3 s with their data and figures (the time the command reports)" in text
    assert distinct_text([0.0085, 0.0091, 0.0094]) == ["0.0085", "0.0091", "0.0094"]
    assert distinct_text([0.009, 0.003, 0.0]) == ["0.009", "0.003", "0.000"]
    assert any("names no authors, journal, year or DOI" in p for p in INTRO)


def test_reproduce_command_line_shows_only_typed_options(tmp_path, monkeypatch):
    from cli_run import run_cli

    import geardyn.reproduce as rep

    seen = {}

    def fake_run(out, settings, log=None, command=None):
        seen["command"] = command
        raise KeyboardInterrupt  # stop before any study runs

    monkeypatch.setattr(rep, "run", fake_run)
    try:
        run_cli(["reproduce", "--out", tmp_path / "r", "--quick"])
    except KeyboardInterrupt:
        pass
    assert "command" in seen, seen
    assert "--workers" not in seen["command"] and "--quick" in seen["command"]
