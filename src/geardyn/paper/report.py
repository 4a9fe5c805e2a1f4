"""The reproduction report: claims with verdicts, rendered as Markdown and self-contained HTML.

A report is a list of :class:`Section` s, each with explanatory text (the settings chosen and
why), figures, and the :class:`Finding` s it holds (a claim of :mod:`geardyn.paper.claims` with
what geardyn computed and the verdict).  :func:`write_report` writes ``report.md``,
``report.html`` (figures embedded as base64 PNG, so the file opens anywhere on its own) and
``claims.json`` into the output directory.  No numerics here.
"""

from __future__ import annotations

import base64
import html
import json
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from ..io import atomic_write_bytes

#: The four verdict kinds, strongest first (the rules that give them: :mod:`geardyn.paper.verdicts`).
VERDICTS = ("reproduced", "reproduced under a reading", "contradicted", "not testable")

#: What a run that is not the full reproduction is called, by :meth:`geardyn.paper.settings.Settings.run_kind`.
RUN_NAMES = {"quick": "quick run", "changed": "run with changed settings"}


@dataclass
class RunInfo:
    """Where a report comes from: the geardyn version, the date, the command line, and whether the
    run is the full reproduction (and if not, what it changed).

    Parameters
    ----------
    version : str
        geardyn's version.
    date : str
        When the run started (ISO 8601, UTC).
    command : str
        The command line that made the report.
    kind : str
        ``"full"``, ``"quick"`` or ``"changed"`` (:meth:`geardyn.paper.settings.Settings.run_kind`).
    changes : list of str
        What the run changes from the full reproduction, one line per setting (empty for the full run).
    """

    version: str
    date: str
    command: str
    kind: str = "full"
    changes: list[str] = field(default_factory=list)

    @property
    def name(self) -> str:
        """What the run is called (:data:`RUN_NAMES`; the kind itself for the full run)."""
        return RUN_NAMES.get(self.kind, self.kind)

    @property
    def reduced(self) -> bool:
        """Whether the run is not the full reproduction."""
        return self.kind != "full"

    def provenance(self) -> str:
        """``"geardyn 0.1.0, run 2026-12-02T12:00:00Z: geardyn reproduce --out results"``."""
        return f"geardyn {self.version}, run {self.date}: {self.command}"

    def banner(self, where: str = "listed below") -> str:
        """What a reduced run is, in two sentences (empty for the full run): the first line of its report
        and of its terminal summary.

        Parameters
        ----------
        where : str
            Where the changed settings are listed.

        Returns
        -------
        str
        """
        if not self.reduced:
            return ""
        what = (
            "reduced grids, fewer points and shorter runs than the full reproduction"
            if self.kind == "quick"
            else "settings that differ from the full reproduction"
        )
        return (
            f"{self.name.capitalize()}: {what} ({len(self.changes)} settings, {where})"
            ". Its verdicts and totals may differ from the full run's (geardyn reproduce without --quick)."
        )


@dataclass
class Finding:
    """One claim of the paper and what geardyn found (made by :meth:`geardyn.paper.claims.Claim.judge`).

    Parameters
    ----------
    id, source, statement : str
        The claim's id, where the paper makes it and its statement.
    computed : str
        What geardyn finds.
    verdict : str
        One of :data:`VERDICTS`.
    evidence : list of str
        Paths relative to the report directory (figures and NetCDF data).
    readings : list of list of str
        The readings tried and the claim's result under each: a small table, first row the header.
    deciding : str
        The evidence that decides the verdict, in one line.
    reading : str
        The reading that reproduces it (verdict "reproduced under a reading"), else empty.
    found : str
        What geardyn finds, in one line for the summary (default: the start of ``computed``).
    table_reading, table_holds : str, bool or None
        The one reading chosen for the claim's whole table (the best for the table as a whole) and whether
        the claim holds under it (None: not computed).

    Raises
    ------
    ValueError
        If ``verdict`` is not one of :data:`VERDICTS`.
    """

    id: str
    source: str
    statement: str
    computed: str
    verdict: str
    evidence: list[str] = field(default_factory=list)
    readings: list[list[str]] = field(default_factory=list)
    deciding: str = ""
    reading: str = ""
    found: str = ""
    table_reading: str = ""
    table_holds: bool | None = None

    def __post_init__(self) -> None:
        if self.verdict not in VERDICTS:
            raise ValueError(f"verdict must be one of {VERDICTS}, got {self.verdict!r}")


@dataclass
class Section:
    """A study: a title, paragraphs (plain text), figures (relative paths) and its claims.

    Parameters
    ----------
    title : str
    paragraphs : list of str
        Plain text: what was computed, the settings chosen and why.
    figures : list of (str, str)
        (path relative to the report directory, caption).
    claims : list of Finding
    table : list of list of str, optional
        A table, first row the header.
    """

    title: str
    paragraphs: list[str] = field(default_factory=list)
    figures: list[tuple[str, str]] = field(default_factory=list)  # (relative path, caption)
    claims: list[Finding] = field(default_factory=list)
    table: list[list[str]] | None = None  # optional table, first row = header


def _md_escape_cell(s: str) -> str:
    return s.replace("|", "\\|").replace("\n", " ")


def _md_table(rows: Sequence[Sequence[str]]) -> list[str]:
    lines = ["| " + " | ".join(_md_escape_cell(x) for x in row) + " |" for row in rows]
    return [lines[0], "|" + "---|" * len(rows[0]), *lines[1:], ""]


#: The summary's "we find" is cut at the first sentence end after this many characters at most.
FOUND_CHARS = 240


def found_text(c: Finding) -> str:
    """What geardyn finds, in one line for the summary: ``found``, else the first sentence of ``computed``."""
    if c.found:
        return c.found
    t = c.computed
    end = t.find(". ")
    t = t if end < 0 else t[: end + 1]
    return t if len(t) <= FOUND_CHARS else t[: FOUND_CHARS - 1].rstrip() + "…"


def _verdict_text(c: Finding) -> str:
    """The verdict as the report writes it: the kind, with the reading where it is one."""
    return f"{c.verdict}: {c.reading}" if c.reading and c.verdict == "reproduced under a reading" else c.verdict


def verdict_counts(claims: Iterable[Finding]) -> str:
    """``"4 reproduced, 7 reproduced under a reading, 15 contradicted, 0 not testable"``: the claims of each verdict.

    Parameters
    ----------
    claims : iterable of Finding

    Returns
    -------
    str
    """
    verdicts = [c.verdict for c in claims]
    return ", ".join(f"{verdicts.count(v)} {v}" for v in VERDICTS)


def totals_text(claims: Sequence[Finding], run: RunInfo | None = None) -> str:
    """``"Totals (26 claims): 4 reproduced, 7 reproduced under a reading, 15 contradicted, 0 not testable."``;
    for a run that is not the full reproduction ``"Totals of this quick run (26 claims): … (may differ
    from the full run)."``

    Parameters
    ----------
    claims : sequence of Finding
    run : RunInfo, optional
        The run (default: the full reproduction).

    Returns
    -------
    str
    """
    text = verdict_counts(claims)
    if run is not None and run.reduced:
        return f"Totals of this {run.name} ({len(claims)} claims): {text} (may differ from the full run)."
    return f"Totals ({len(claims)} claims): {text}."


#: Claims the paper states from one setting (a table, or a study's text beside its table): judged together
#: under one reading (:func:`one_reading_totals`).  A claim in no group is a group of its own.
CLAIM_GROUPS: dict[str, tuple[str, ...]] = {
    "Table 2 and the damping study": ("T2-1", "T2-2", "T2-3", "T2-4", "T2-5", "XI0-BIF", "XI1-CHAOS"),
    "Table 3 and the backlash study": ("T3-1", "T3-2", "T3-3", "BL-IMPACT", "BL-AMP"),
    "the jump study": ("JUMP-LOW", "JUMP-XI0", "JUMP-XI1", "JUMP-FLUCT"),
    "the backlash jumps": ("JUMP-057", "JUMP-082", "JUMP-095"),
    "Table 4": ("T4-1", "T4-2", "T4-3", "T4-4", "T4-5"),
}
DEFAULT_READING = "the default reading"
#: The counts of :func:`one_reading_totals`, in the order the totals give them.
ONE_READING_COUNTS = ("reproduced", "reproduced under the group's reading", "not reproduced", "not testable")


def one_reading(claims: Sequence[Finding]) -> tuple[str, list[bool]]:
    """The one reading of a group of claims under which most of them hold, and which hold under it.

    The candidates are the default reading (the claims reproduced there), each reading a claim of the group
    was confirmed under (the claims confirmed under exactly that reading) and the reading chosen for the
    whole table (the claims that hold under it).  A claim counts under a reading only where it was confirmed
    under that reading, so the count is a lower bound.

    Parameters
    ----------
    claims : sequence of Finding
        One group.

    Returns
    -------
    (str, list of bool)
        The reading (:data:`DEFAULT_READING` on a tie) and, per claim, whether it holds under it.
    """
    cands: dict[str, list[bool]] = {DEFAULT_READING: [c.verdict == "reproduced" for c in claims]}
    for c in claims:
        if c.verdict == "reproduced under a reading" and c.reading and c.reading not in cands:
            cands[c.reading] = [d.verdict == "reproduced under a reading" and d.reading == c.reading for d in claims]
        if c.table_reading:
            hold = cands.setdefault(c.table_reading, [False] * len(claims))
            for i, d in enumerate(claims):
                hold[i] = hold[i] or (d.table_reading == c.table_reading and bool(d.table_holds))
    best = max(cands, key=lambda r: (sum(cands[r]), r == DEFAULT_READING))
    return best, cands[best]


def one_reading_totals(claims: Sequence[Finding]) -> dict[str, Any]:
    """Totals with one reading per table or study (:data:`CLAIM_GROUPS`), the reading chosen per group.

    Returns
    -------
    dict
        ``reproduced`` (at the default reading), ``reproduced under the group's reading``, ``not reproduced``
        (contradicted, or confirmed only under another reading than the group's), ``not testable``, and
        ``groups``: group name → (reading, claims holding, claims).
    """
    ids = {c.id: c for c in claims}
    groups = [(name, g) for name, members in CLAIM_GROUPS.items() if (g := [ids[m] for m in members if m in ids])]
    grouped = {m for members in CLAIM_GROUPS.values() for m in members}
    groups += [(c.id, [c]) for c in claims if c.id not in grouped]
    out: dict[str, Any] = {**dict.fromkeys(ONE_READING_COUNTS, 0), "groups": {}}
    for name, group in groups:
        reading, holds = one_reading(group)
        for c, h in zip(group, holds, strict=True):
            if c.verdict == "not testable":
                out["not testable"] += 1
            elif h:
                out["reproduced" if reading == DEFAULT_READING else "reproduced under the group's reading"] += 1
            else:
                out["not reproduced"] += 1
        out["groups"][name] = (reading, sum(holds), len(group))
    return out


def one_reading_text(claims: Sequence[Finding], run: RunInfo | None = None) -> str:
    """``"Totals under one reading per table or study (26 claims, 10 groups): …"``, said before the per-claim
    totals (:func:`totals_text`)."""
    t = one_reading_totals(claims)
    counts = ", ".join(f"{t[k]} {k}" for k in ONE_READING_COUNTS)
    where = f" of this {run.name}" if run is not None and run.reduced else ""
    head = f"Totals{where} under one reading per table or study ({len(claims)} claims, {len(t['groups'])} groups)"
    return f"{head}: {counts}."


def one_reading_details(claims: Sequence[Finding]) -> str:
    """The reading chosen for each group of several claims, in one paragraph."""
    t = one_reading_totals(claims)
    parts = [f"{name}: {reading} ({k} of {n})" for name, (reading, k, n) in t["groups"].items() if n > 1]
    return "One reading per group: " + "; ".join(parts) + "." if parts else ""


#: Column headers of the summary table.
SUMMARY_COLUMNS = ("id", "source", "paper says", "we find", "verdict", "deciding evidence")


def dataset_of(path: str) -> str:
    """The name of the saved Dataset a report path belongs to (``data/<name>.nc``, ``figures/<name>/…``).

    Parameters
    ----------
    path : str
        A path relative to the report directory.

    Returns
    -------
    str
        The name, or ``path`` itself for any other path.
    """
    parts = path.split("/")
    if len(parts) == 2 and parts[0] == "data":
        return parts[1].rsplit(".", 1)[0]
    if len(parts) >= 3 and parts[0] == "figures":
        return parts[1]
    return path


def _evidence(
    evidence: Sequence[str], labels: Mapping[str, str], link: Callable[[str, str], str], text: Callable[[str], str]
) -> str:
    """Evidence grouped by Dataset in first-cited order, each as its label (``text``) and links (``link(kind,
    path)``): ``"label (figure, data); label (data)"``."""
    groups: dict[str, list[tuple[str, str]]] = {}
    for p in dict.fromkeys(evidence):
        kind = "figure" if p.startswith("figures/") and p.endswith(".png") else "data"  # a drawn figure: a PNG
        groups.setdefault(dataset_of(p), []).append((kind, p))
    return "; ".join(
        f"{text(labels.get(n, n))} (" + ", ".join(link(k, p) for k, p in items) + ")" for n, items in groups.items()
    )


def _anchor(path: str) -> str:
    return "fig-" + "".join(ch if ch.isalnum() else "-" for ch in path)


def render_markdown(
    title: str,
    intro: Sequence[str],
    sections: Sequence[Section],
    labels: Mapping[str, str] | None = None,
    run: RunInfo | None = None,
) -> str:
    """The report as Markdown: the totals, the table of claims (what the paper says, what geardyn
    finds, the verdict), then every section.

    Parameters
    ----------
    title : str
    intro : sequence of str
        Paragraphs before the claims.
    sections : sequence of Section
    labels : mapping, optional
        Dataset name → what it is (with its parameters): the text of the evidence links.
    run : RunInfo, optional
        Where the report comes from, written under the title; a run that is not the full
        reproduction says so there, with what it changed, and in its title and totals.

    Returns
    -------
    str
    """
    labels = labels or {}
    claims = [c for s in sections for c in s.claims]
    out = [f"# {_title(title, run)}", ""]
    if run is not None:
        out += [f"*{run.provenance()}*", ""]
        if run.reduced:
            out += [f"> **{run.banner()}**", ">"] + [f"> - {ch}" for ch in run.changes] + [""]
    out += [p + "\n" for p in intro]
    out += [
        "## Claims and verdicts",
        "",
        f"**{one_reading_text(claims, run)}**",
        "",
        one_reading_details(claims),
        "",
        "Per claim, each under its own nearest reading: " + totals_text(claims, run),
        "",
    ]
    out += _md_table(
        [SUMMARY_COLUMNS]
        + [[c.id, c.source, c.statement, found_text(c), f"**{_verdict_text(c)}**", c.deciding] for c in claims]
    )
    for s in sections:
        out += [f"## {s.title}", ""]
        out += [p + "\n" for p in s.paragraphs]
        if s.table:
            out += _md_table(s.table)
        for c in s.claims:
            ev = _evidence(c.evidence, labels, lambda k, p: f"[{k}]({p})", str)
            out += [
                f"**{c.id}** ({c.source}). *Paper:* {c.statement}",
                "",
                f"*geardyn:* {c.computed}",
                "",
                f"*Verdict:* **{_verdict_text(c)}**. Deciding: {c.deciding}. Evidence: {ev}",
                "",
            ]
            if c.readings:
                out += _md_table(c.readings)
        for path, caption in s.figures:
            out += [f"![{caption}]({path})", "", f"*{caption}*", ""]
    return "\n".join(out)


def _title(title: str, run: RunInfo | None) -> str:
    return f"{title} ({run.name})" if run is not None and run.reduced else title


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1200px;margin:2em auto;
padding:0 1em;color:#222;line-height:1.45}
table{border-collapse:collapse;margin:1em 0;font-size:0.92em}td,th{border:1px solid #ccc;padding:4px 8px;
vertical-align:top;text-align:left}th{background:#f3f3f3}
table.summary td:nth-child(3){min-width:14em}table.summary td:nth-child(4){min-width:18em}
table.summary td:nth-child(5){min-width:9em;max-width:16em}table.summary td:nth-child(6){min-width:16em}
.v-reproduced{background:#d9f2d9}.v-reading{background:#e3ecfa}.v-contradicted{background:#f8d7d7}
.v-untestable{background:#eeeeee}table.readings{font-size:0.85em;margin:0.4em 0}
.totals{font-size:1.05em}
figure{margin:1em 0}figure img{max-width:100%;border:1px solid #ddd}figcaption{font-size:0.9em;color:#555}
.claim{border-left:4px solid #999;padding:0.3em 0.8em;margin:1em 0;background:#fafafa}
code{background:#f2f2f2;padding:0 3px}
.provenance{color:#555;font-size:0.9em}
.reduced{border:2px solid #c77700;background:#fff4e0;padding:0.6em 1em;margin:1em 0}
.reduced ul{columns:2;font-size:0.88em;margin:0.4em 0}
"""


def _vclass(v: str) -> str:
    return "v-" + {"reproduced under a reading": "reading", "not testable": "untestable"}.get(v, v)


def _html_table(rows: Sequence[Sequence[str]], cls: str = "") -> str:
    e = html.escape
    head = f"<table class='{cls}'>" if cls else "<table>"
    body = "".join("<tr>" + "".join(f"<td>{e(x)}</td>" for x in row) + "</tr>" for row in rows[1:])
    return head + "<tr>" + "".join(f"<th>{e(h)}</th>" for h in rows[0]) + "</tr>" + body + "</table>"


def _img(directory: Path, rel: str) -> str:
    p = directory / rel
    if not p.exists():
        return f"<p>(missing figure {html.escape(rel)})</p>"
    data = base64.b64encode(p.read_bytes()).decode("ascii")
    return f'<img alt="{html.escape(rel)}" src="data:image/png;base64,{data}">'


def render_html(
    title: str,
    intro: Sequence[str],
    sections: Sequence[Section],
    directory: Path,
    labels: Mapping[str, str] | None = None,
    run: RunInfo | None = None,
) -> str:
    """The report as one self-contained HTML page (figures embedded as base64 PNG).

    The totals come first, then the table of claims (what the paper says, what geardyn finds, the
    verdict), then every section; evidence is linked by what it is (``labels``), a figure shown in
    the page to its place there.

    Parameters
    ----------
    title : str
    intro : sequence of str
    sections : sequence of Section
    directory : Path
        The report directory the figure paths are relative to.
    labels : mapping, optional
        Dataset name → what it is (with its parameters): the text of the evidence links.
    run : RunInfo, optional
        Where the report comes from (version, date, command line), shown under the title; a run that
        is not the full reproduction says so in a box there, with what it changed, and in its title
        and totals.

    Returns
    -------
    str
    """
    e = html.escape
    labels = labels or {}
    claims = [c for s in sections for c in s.claims]
    shown = {p for s in sections for p, _ in s.figures}
    head = _title(title, run)
    out = [
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{e(head)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{e(head)}</h1>",
    ]
    if run is not None:
        out.append(
            f"<p class='provenance'>geardyn {e(run.version)} &middot; run {e(run.date)} &middot; command: "
            f"<code>{e(run.command)}</code></p>"
        )
        if run.reduced:
            out.append(
                f"<div class='reduced'><b>{e(run.banner())}</b><ul>"
                + "".join(f"<li>{e(ch)}</li>" for ch in run.changes)
                + "</ul></div>"
            )
    out += [f"<p>{e(p)}</p>" for p in intro]
    out.append("<h2>Claims and verdicts</h2>")
    out.append(f"<p class='totals'><b>{e(one_reading_text(claims, run))}</b></p>")
    out.append(f"<p>{e(one_reading_details(claims))}</p>")
    out.append(f"<p class='totals'>Per claim, each under its own nearest reading: {e(totals_text(claims, run))}</p>")
    out.append("<table class='summary'><tr>" + "".join(f"<th>{e(h)}</th>" for h in SUMMARY_COLUMNS) + "</tr>")
    for c in claims:
        out.append(
            f"<tr><td><a href='#{e(c.id)}'>{e(c.id)}</a></td><td>{e(c.source)}</td><td>{e(c.statement)}</td>"
            f"<td>{e(found_text(c))}</td><td class='{_vclass(c.verdict)}'>{e(_verdict_text(c))}</td>"
            f"<td>{e(c.deciding)}</td></tr>"
        )
    out.append("</table>")

    def link(kind: str, path: str) -> str:
        href = "#" + _anchor(path) if path in shown else path
        return f"<a href='{e(href)}'>{e(kind)}</a>"

    for s in sections:
        out.append(f"<h2>{e(s.title)}</h2>")
        out += [f"<p>{e(p)}</p>" for p in s.paragraphs]
        if s.table:
            out.append(_html_table(s.table))
        for c in s.claims:
            ev = _evidence(c.evidence, labels, link, e)
            out.append(
                f"<div class='claim' id='{e(c.id)}'><b>{e(c.id)}</b> ({e(c.source)})<br><i>Paper:</i> {e(c.statement)}"
                f"<br><i>geardyn:</i> {e(c.computed)}<br><i>Verdict:</i> <span class='{_vclass(c.verdict)}'>"
                f"<b>{e(_verdict_text(c))}</b></span> &mdash; deciding: {e(c.deciding)} &mdash; evidence: {ev}"
                + (_html_table(c.readings, "readings") if c.readings else "")
                + "</div>"
            )
        for path, caption in s.figures:
            out.append(
                f"<figure id='{_anchor(path)}'>{_img(directory, path)}<figcaption>{e(caption)}</figcaption></figure>"
            )
    out.append("</body></html>")
    return "\n".join(out)


def write_report(
    directory: str | Path,
    title: str,
    intro: Sequence[str],
    sections: Sequence[Section],
    meta: dict[str, Any] | None = None,
    labels: Mapping[str, str] | None = None,
    run: RunInfo | None = None,
) -> dict[str, Path]:
    """Write report.md, report.html, claims.json (a list, one entry per claim) and, with ``meta``,
    run.json (settings, timings) into ``directory``.

    Parameters
    ----------
    directory : str or Path
        Created if needed; every file is written atomically.
    title : str
    intro : sequence of str
    sections : sequence of Section
    meta : dict, optional
        Written as run.json.
    labels : mapping, optional
        Dataset name → what it is, with its parameters (the text of the evidence links).
    run : RunInfo, optional
        Where the report comes from (:func:`render_html`); also written into run.json.

    Returns
    -------
    dict
        ``md``, ``html``, ``claims`` (and ``meta``) → path.
    """
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    every = [c for s in sections for c in s.claims]
    paths = {"md": d / "report.md", "html": d / "report.html", "claims": d / "claims.json"}
    atomic_write_bytes(paths["md"], render_markdown(title, intro, sections, labels, run).encode())
    atomic_write_bytes(paths["html"], render_html(title, intro, sections, d, labels, run).encode())
    atomic_write_bytes(paths["claims"], json.dumps([asdict(c) for c in every], indent=2, default=str).encode())
    if run is not None:
        meta = {
            "run": asdict(run),
            "totals_one_reading": one_reading_text(every, run),
            "totals": totals_text(every, run),
            **(meta or {}),
        }
    if meta:
        paths["meta"] = d / "run.json"
        atomic_write_bytes(paths["meta"], json.dumps(meta, indent=2, default=str).encode())
    return paths
