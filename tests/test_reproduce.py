"""`geardyn reproduce` end to end on a reduced run: the report's structure, claims and evidence."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from typer.testing import CliRunner

from geardyn.analysis.classify import MOTION_CHAOTIC, MOTION_PERIODIC, MOTION_QUASIPERIODIC
from geardyn.cli import app
from geardyn.paper import CLAIMS, TABLE1, TABLE1_MODEL, TABLE3, TABLE4
from geardyn.paper.claims import claim_ids
from geardyn.paper.report import Finding, Section
from geardyn.paper.run import link_figures
from geardyn.paper.studies.formula import fit_formula
from geardyn.paper.verdicts import is_chaotic, is_regular, motion_rule, quasi_n, verdict_of


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce")
    res = CliRunner().invoke(app, ["reproduce", "--quick", "--workers", "1", "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout)
    return out, summary


def test_report_files_and_claims(report_dir):
    out, summary = report_dir
    for name in ("report.html", "report.md", "claims.json"):
        assert (out / name).stat().st_size > 0
    claims = json.loads((out / "claims.json").read_text())
    ids = [c["id"] for c in claims]
    assert sorted(ids) == sorted(CLAIMS)  # every claim of the paper, each once
    # every row of Tables 2, 3 and 4 is a claim
    assert {f"T2-{i}" for i in range(1, 6)} <= set(ids)
    assert {f"T3-{i}" for i in range(1, len(TABLE3) + 1)} <= set(ids)
    assert {f"T4-{i}" for i in range(1, len(TABLE4) + 1)} <= set(ids)
    for c in claims:
        assert set(c) == {
            "id",
            "source",
            "statement",
            "computed",
            "verdict",
            "evidence",
            "readings",
            "deciding",
            "reading",
            "found",
            "table_reading",
            "table_holds",
        }
        assert c["verdict"] in ("reproduced", "reproduced under a reading", "contradicted", "not testable")
        # every claim shows the readings it was judged under, with its result under each, and why the verdict
        assert c["readings"][0] == ["reading", "result", "holds"] and len(c["readings"]) >= 2, c["id"]
        assert c["deciding"], c["id"]
        assert (c["verdict"] == "reproduced under a reading") == bool(c["reading"]), c["id"]
        if c["reading"]:
            assert any(row[2] in ("yes", "confirmed") for row in c["readings"][1:]), c["id"]
        assert c["computed"] and c["statement"] == CLAIMS[c["id"]].statement
        assert c["evidence"], c["id"]
        for rel in c["evidence"]:
            assert not rel.startswith("/")
            assert (out / rel).is_file(), f"{c['id']}: missing evidence {rel}"
    assert [c["id"] for c in summary["claims"]] == ids


def test_html_is_self_contained(report_dir):
    out, _ = report_dir
    html = (out / "report.html").read_text()
    srcs = re.findall(r"<img[^>]*src=\"([^\"]+)\"", html)
    assert srcs and all(s.startswith("data:image/png;base64,") for s in srcs)
    assert "missing figure" not in html
    for cid in CLAIMS:
        assert f"id='{cid}'" in html


def test_markdown_lists_every_claim_with_its_verdict(report_dir):
    out, _ = report_dir
    md = (out / "report.md").read_text()
    claims = json.loads((out / "claims.json").read_text())
    for c in claims:
        shown = c["verdict"] + (f": {c['reading']}" if c["reading"] else "")
        assert f"| {c['id']} |" in md and f"**{shown}**" in md


def test_formula_fit_recovers_known_coefficients():
    rng = np.random.default_rng(1)
    w = rng.uniform(0.3, 1.2, 200)
    xi0 = rng.choice([0.08, 0.1, 0.15], 200)
    b = rng.choice([0.2, 0.5, 1.5], 200)
    A = 0.3 + 0.7 * np.sin(np.pi * w) * np.exp(-xi0 * w) + 0.12 * b**2
    fit = fit_formula(w, xi0, b, A)
    assert fit["A0"] == pytest.approx(0.3, abs=1e-10)
    assert fit["dA"] == pytest.approx(0.7, abs=1e-10)
    assert fit["beta"] == pytest.approx(0.12, abs=1e-10)
    assert fit["r2"] == pytest.approx(1.0, abs=1e-12)


def test_verdict_rule_and_quasi_n_mapping():
    assert verdict_of(0.8) == "reproduced" and verdict_of(0.5) == "contradicted"
    assert verdict_of(0.1) == "contradicted"
    q4 = quasi_n(4)
    assert q4(MOTION_PERIODIC, 4, 0)
    # F1: no invariant closed curves for ξ0 > 0, so "quasi-4-periodic" is period-4 only, never 4 loops
    assert not q4(MOTION_QUASIPERIODIC, 0, 4)
    assert not q4(MOTION_PERIODIC, 2, 0) and not q4(MOTION_CHAOTIC, 0, 0)


def test_every_claim_carries_the_numbers_of_its_statement():
    for cid, claim in CLAIMS.items():
        assert claim.id == cid and claim.source and claim.statement
        for key, value in claim.numbers.items():
            for v in value if isinstance(value, tuple) else (value,):
                if isinstance(v, float):  # every number the claim is judged by is one the paper states
                    assert f"{v:g}" in claim.statement, (cid, key, v)
        if "motion" in claim.numbers:
            motion_rule(claim.numbers["motion"])  # every motion word has a reading
    assert claim_ids("T3-") == ["T3-1", "T3-2", "T3-3"] and len(TABLE4) == len(claim_ids("T4-")) == 5
    assert TABLE3[1] == (0.7, 0.35, "quasi-2-periodic", "moderate", "near zero")
    with pytest.raises(TypeError):
        CLAIMS["T2-1"].numbers["hi"] = 0.5  # read-only


def test_table1_is_the_model_defaults_and_the_packaged_pair():
    from geardyn.config import load_config

    m = load_config(None).model
    assert TABLE1_MODEL.omega == 1.0
    assert dict(TABLE1) == {"xi0": m.xi0, "xi1": m.xi[0], "kappa1": m.kappa[0], "fp": m.fp, "eps1": m.eps[0], "D": m.D}


def test_motion_words():
    assert motion_rule("chaotic") == (is_chaotic, "chaotic")
    assert motion_rule("quasi-periodic") == (is_regular, "regular (periodic or quasi-periodic)")
    q3, what = motion_rule("quasi-3-periodic")
    assert (
        what == "quasi-3-periodic (read as period-3, by F1)"
        and q3(MOTION_PERIODIC, 3, 0)
        and not q3(MOTION_PERIODIC, 2, 0)
    )
    with pytest.raises(ValueError):
        motion_rule("periodic-ish")


def test_figure_references_become_the_drawn_files():
    f = CLAIMS["FORMULA"].judge("fit", "reproduced", ["data/formula_fit.nc", "figure:formula_fit"])
    assert isinstance(f, Finding) and f.statement == CLAIMS["FORMULA"].statement
    s = Section("t", figures=[("figure:formula_fit", "caption")], claims=[f])
    link_figures([s], {"formula_fit": ["figures/formula_fit/formula_fit.png"]})
    assert s.figures == [("figures/formula_fit/formula_fit.png", "caption")]
    assert f.evidence == ["data/formula_fit.nc", "figures/formula_fit/formula_fit.png"]
    with pytest.raises(ValueError, match="no figure was drawn for 'search'"):
        link_figures([Section("t", figures=[("figure:search", "c")])], {})


def test_reproduce_module_keeps_its_names():
    from geardyn import reproduce

    assert reproduce.fit_formula is fit_formula and reproduce.verdict_of is verdict_of
    assert callable(reproduce.run) and reproduce.Settings.quick().workers == 1


# --- the report as a reader sees it (issue: summary, totals, figures, titles, wording) ----------------------------
def _findings(out):
    return [Finding(**c) for c in json.loads((out / "claims.json").read_text())]


def test_summary_table_says_what_the_paper_claims_and_the_totals_come_first(report_dir):
    from geardyn.paper.report import SUMMARY_COLUMNS

    out, _ = report_dir
    page = (out / "report.html").read_text()
    header = "<tr>" + "".join(f"<th>{h}</th>" for h in SUMMARY_COLUMNS) + "</tr>"
    assert "paper says" in SUMMARY_COLUMNS and page.count(header) == 1
    totals = page.index("Totals of this quick run (")
    assert totals < page.index(header)
    claims = _findings(out)
    kinds = ("reproduced", "reproduced under a reading", "contradicted", "not testable")
    counts = {v: sum(c.verdict == v for c in claims) for v in kinds}
    assert (
        f"{counts['reproduced']} reproduced, {counts['reproduced under a reading']} reproduced under a reading, "
        f"{counts['contradicted']} contradicted, {counts['not testable']} not testable"
    ) in page[totals : totals + 300]
    summary = page[page.index(header) : page.index("</table>", page.index(header))]
    for c in claims:
        row = re.search(rf"<tr><td><a href='#{re.escape(c.id)}'>.*?</tr>", summary).group(0)
        from geardyn.paper.report import found_text

        assert html_escape(c.statement) in row and html_escape(found_text(c)) in row and c.verdict in row
        assert c.computed.startswith(found_text(c).rstrip("…"))
        assert html_escape(c.deciding) in row
    md = (out / "report.md").read_text()
    assert md.index("Totals of this quick run (") < md.index(
        "| id | source | paper says | we find | verdict | deciding evidence |"
    )


def html_escape(s):
    import html

    return html.escape(s)


def test_every_figure_shown_exists_and_every_cited_figure_is_shown(report_dir):
    out, _ = report_dir
    page = (out / "report.html").read_text()
    shown = re.findall(r"<img alt=\"([^\"]+)\"", page)
    assert shown and len(shown) == len(set(shown))
    for rel in shown:
        assert (out / rel).is_file(), rel
    drawn = json.loads((out / "run.json").read_text())["figures"]
    for c in _findings(out):
        for rel in c.evidence:
            if rel.endswith(".png"):
                assert rel in shown, f"{c.id} cites {rel}, which the report does not show"
            elif rel.startswith("data/"):  # cited data: its main figure is shown too (the ω-search heat maps)
                name = rel[len("data/") : -len(".nc")]
                assert not drawn[name] or drawn[name][0] in shown, f"{c.id} cites {rel}; its figure is not shown"


def test_every_figure_is_titled_with_its_parameters(report_dir):
    out, _ = report_dir
    page = (out / "report.html").read_text()
    captions = re.findall(r"<figcaption>(.*?)</figcaption>", page)
    assert len(captions) == len(re.findall(r"<img ", page))
    for cap in captions:
        assert re.search(r"(ω|ξ0|ξ1|D) = \d", cap), cap
    response = [c for c in captions if c.startswith("Frequency response")]
    from geardyn.reproduce import Settings

    n = len(Settings.quick().response_sets)  # eight responses, eight different titles
    assert n == 8 and len(response) == len(set(response)) == n
    for name in json.loads((out / "run.json").read_text())["datasets"]:
        ds = __import__("xarray").open_dataset(out / "data" / f"{name}.nc")
        assert "model" in ds.attrs, f"{name}: figures title from the model, which the Dataset must carry"
        ds.close()


def test_report_text_uses_symbols_and_consistent_verdict_words(report_dir):
    from test_report import check_report_text, check_verdict_wording, markdown_text, visible_text

    out, _ = report_dir
    check_report_text(visible_text((out / "report.html").read_text()))
    check_report_text(markdown_text((out / "report.md").read_text()))
    claims = _findings(out)
    check_verdict_wording(claims)
    by_id = {c.id: c for c in claims}
    m = re.search(r"for (\d+) of (\d+) backlash values", by_id["JUMP-057"].computed)
    assert m and (int(m.group(1)) == int(m.group(2)) or by_id["JUMP-057"].verdict != "reproduced")
    assert "= none" not in by_id["BL-IMPACT"].computed


def test_continuation_figure_draws_its_up_down_sweep(report_dir):
    import xarray as xr

    from geardyn.io import attached
    from geardyn.plot.periodic import SWEEP_CONTEXT, continuation_figure
    from geardyn.reproduce import Settings

    out, _ = report_dir
    ds = xr.load_dataset(out / "data" / "jump_continuation.nc")
    sweep = attached(ds, SWEEP_CONTEXT)
    s = Settings.quick()
    assert sweep is not None and list(sweep["sweep"].values) == ["up", "down"]
    assert sweep["omega"].size == s.continuation_sweep_num
    assert (
        float(sweep["omega"].min()) == s.continuation_omega[0]
        and float(sweep["omega"].max()) == s.continuation_omega[1]
    )
    art = continuation_figure(ds)
    labels = [h.get_label() for a in art.axes if a is not None for h in a.get_lines() + a.collections]
    assert any("sweep up" in lab for lab in labels) and any("sweep down" in lab for lab in labels)
    assert "up/down sweep" in art.axes[0].get_title()


def test_xi0_diagram_is_also_shown_over_its_structure(report_dir):
    import xarray as xr

    from geardyn.reproduce import Settings

    out, _ = report_dir
    lo, hi = Settings.quick().xi0_zoom
    full = xr.load_dataset(out / "data" / "xi0_bifurcation.nc")
    zoom = xr.load_dataset(out / "data" / "xi0_bifurcation_zoom.nc")
    x = full["xi0"].values
    assert list(zoom["xi0"].values) == [v for v in x if lo <= v <= hi] and zoom["xi0"].size < x.size
    assert zoom.attrs["geardyn_kind"] == "bifurcation"
    assert "figures/xi0_bifurcation_zoom/bifurcation.png" in (out / "report.html").read_text()


def test_report_shows_the_readings_of_every_claim_f1_f2_and_the_three_tables(report_dir):
    import xarray as xr

    out, _ = report_dir
    page = (out / "report.html").read_text()
    for title in (
        "F1: the period map contracts every area",
        "F2: without back-flank contact the response does not depend on D",
        "Table 2 recomputed",
        "Table 3 recomputed",
        "Table 4 recomputed",
        "Readings",
    ):
        assert f"<h2>{title}</h2>" in page, title
    for cid in CLAIMS:  # every claim block holds its readings table
        block = page[page.index(f"<div class='claim' id='{cid}'>") :]
        block = block[: block.index("</div>")]
        assert "<table class='readings'><tr><th>reading</th><th>result</th><th>holds</th></tr>" in block, cid
    for cid in claim_ids("T2-") + claim_ids("T3-") + claim_ids("T4-"):  # the paper's rows beside geardyn's
        word = CLAIMS[cid].numbers.get("motion") or CLAIMS[cid].numbers["jump"]
        assert f"<td>{word}</td>" in page, cid
    f1 = xr.load_dataset(out / "data" / "facts_f1.nc")
    assert float(f1["rel"].max()) < 1e-8  # det of the period map = exp(−4πξ0/ω)
    f2 = xr.load_dataset(out / "data" / "facts_f2.nc")
    free = f2["back"].values == 0
    assert free.any() and (~free).any() and float(np.ptp(f2["amplitude"].values[free])) < 1e-9
    run = json.loads((out / "run.json").read_text())
    assert {"readings_screen", "readings_responses"} <= set(run["datasets"])


# --- a quick report says so; where a report comes from; the comparisons drawn on one axes ------------------------
def test_a_quick_report_says_it_is_quick_with_its_version_date_and_command(report_dir):
    from datetime import datetime

    import geardyn
    from geardyn.reproduce import Settings

    out, summary = report_dir
    page = (out / "report.html").read_text()
    assert "<h1>geardyn reproduction of the spiral bevel gear paper (quick run)</h1>" in page
    box = page[page.index("<div class='reduced'>") : page.index("</div>", page.index("<div class='reduced'>"))]
    assert page.index("<div class='reduced'>") < page.index("<h2>Claims and verdicts</h2>")
    assert "Quick run: reduced grids" in box and "may differ from the full run" in box
    assert box.count("<li>") == len(Settings.quick().changes()) >= 15
    assert "points of each frequency response: 12 (full run: 91)" in box
    command = f"geardyn reproduce --out {out} --quick --workers 1 --json"
    head = page[: page.index("<div class='reduced'>")]
    assert f"geardyn {geardyn.__version__}" in head and command in head
    run = json.loads((out / "run.json").read_text())["run"]
    assert run["version"] == geardyn.__version__ and run["command"] == command and run["kind"] == "quick"
    assert run["changes"] == Settings.quick().changes()
    datetime.fromisoformat(run["date"].replace("Z", "+00:00"))
    assert summary["run"] == run  # the --json summary carries the same
    assert [c["statement"] for c in summary["claims"]] == [CLAIMS[c["id"]].statement for c in summary["claims"]]


def test_the_compared_responses_are_overlaid_and_cited_by_the_claims_that_compare_them(report_dir):
    import xarray as xr

    from geardyn.paper.studies.jumps import response_key
    from geardyn.reproduce import Settings

    out, _ = report_dir
    s = Settings.quick()
    page = (out / "report.html").read_text()
    claims = {c.id: c for c in _findings(out)}
    section = page[
        page.index("<h2>Jumps and fluctuations") : page.index("<h2>", page.index("<h2>Jumps and fluctuations") + 5)
    ]
    shown = re.findall(r"<img alt=\"([^\"]+)\"", section)
    assert shown[:3] == [f"figures/responses_over_{p}/response_overlay.png" for p in ("xi0", "xi1", "D")]
    assert len(shown) == 3 + len(s.response_sets)  # the overlays first, then each response on its own
    for cid, p in (("JUMP-XI0", "xi0"), ("JUMP-XI1", "xi1"), ("JUMP-057", "D"), ("JUMP-082", "D"), ("T4-3", "xi0")):
        assert claims[cid].evidence[0] == f"figures/responses_over_{p}/response_overlay.png", cid
    assert {f"figures/responses_over_{p}/response_overlay.png" for p in ("xi0", "xi1")} <= set(
        claims["JUMP-FLUCT"].evidence
    )
    for p, attr in (("xi0", "xi0_set"), ("xi1", "xi1_set"), ("D", "d_set")):
        ov = xr.load_dataset(out / "data" / f"responses_over_{p}.nc")
        keys = getattr(s, attr)
        assert list(ov["value"].values) == [k[{"xi0": 0, "xi1": 1, "D": 2}[p]] for k in keys]
        for i, k in enumerate(keys):  # the responses themselves, on one ω grid
            r = xr.load_dataset(out / "data" / f"{response_key(*k)}.nc")
            np.testing.assert_array_equal(ov["amplitude"].values[i], r["amplitude"].sel(sweep=["up", "down"]).values)
            np.testing.assert_array_equal(ov["omega"].values, r["omega"].values)
    marks = [m[0] for m in json.loads(xr.load_dataset(out / "data" / "responses_over_D.nc").attrs["marks"])]
    assert marks == [0.5, 0.57, 0.82, 0.95]  # the ω the backlash claims name


def test_the_stability_caption_says_what_its_gaps_are(report_dir):
    import xarray as xr

    out, _ = report_dir
    page = (out / "report.html").read_text()
    cap = re.search(
        r"<figure id='fig-figures-stability-condition[^']*'>.*?<figcaption>(.*?)</figcaption>", page, re.S
    ).group(1)
    ds = xr.load_dataset(out / "data" / "stability_condition.nc")
    kinds = ds["bifurcation_type"].values.astype(str)
    assert "Markers: the ξ0 below which the period-1 response of the full model" in cap
    if np.all(np.isfinite(ds["xi0_critical"].values)):
        assert "(no gaps)" in cap
    else:
        assert "Gaps (" in cap and any(k in cap for k in kinds)
