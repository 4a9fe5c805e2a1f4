"""`geardyn reproduce` end to end on a reduced run: the report's structure, claims and evidence."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from typer.testing import CliRunner

from geardyn.cli import app
from geardyn.paper import CLAIMS, TABLE3, TABLE4
from geardyn.reproduce import fit_formula, quasi_n, verdict_of
from geardyn.analysis.classify import MOTION_PERIODIC, MOTION_QUASIPERIODIC, MOTION_CHAOTIC


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
        assert set(c) == {"id", "source", "statement", "computed", "verdict", "evidence"}
        assert c["verdict"] in ("reproduced", "partly reproduced", "not reproduced")
        assert c["computed"] and c["statement"] == CLAIMS[c["id"]][1]
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
        assert f"| {c['id']} |" in md and f"**{c['verdict']}**" in md


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
    assert verdict_of(0.8) == "reproduced" and verdict_of(0.5) == "partly reproduced"
    assert verdict_of(0.1) == "not reproduced"
    q4 = quasi_n(4)
    assert q4(MOTION_PERIODIC, 4, 0) and q4(MOTION_QUASIPERIODIC, 0, 4)
    assert not q4(MOTION_PERIODIC, 2, 0) and not q4(MOTION_CHAOTIC, 0, 0)
