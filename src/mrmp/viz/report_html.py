"""A benchmark report as one self-contained HTML page: the compact table and the plots first, then the detail.

The page reads top-down: a compact table of success and SoC/LB, one row per
map and N and one column per policy (:func:`compact_table`, the table of the
README); the plots; what was run; the headline table of every configuration,
map by map; and the notes (timeouts, errors, collisions).

The page is plain HTML with inline CSS (no script, nothing fetched): every
plot is embedded as a base64 ``data:`` URI, and also written as a PNG file in
``<report stem>_plots/`` next to the page. Every string taken from the
results is escaped.

Examples
--------
>>> import tempfile, pathlib
>>> from mrmp.io.report_input import BenchRecord, BenchResults, FaultSetting
>>> record = BenchRecord("r0", "done", "empty-8-8", 4, "pibt", 0, FaultSetting(), False, success=True,
...                      soc_over_lb=1.2, makespan=9, wall_time_per_step_s=0.001, messages_per_robot_move=2.5,
...                      collisions=0)
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> files = write_report(BenchResults(folder / "results.jsonl", (record,)), folder / "report.html")
>>> files.plots_folder.name, [plot.path.name for plot in files.plots]
('report_plots', ['empty-8-8-vs-n.png'])
>>> page = files.html.read_text()
>>> "<h3>empty-8-8</h3>" in page, page.count('src="data:image/png;base64,')
(True, 1)
>>> page.index('id="summary"') < page.index('id="plots"') < page.index('id="detail"')
True
"""

from __future__ import annotations

import base64
import os
from collections.abc import Sequence
from dataclasses import dataclass
from html import escape
from pathlib import Path

from mrmp.bench.aggregate import (
    BenchOverview,
    GroupSummary,
    TextTable,
    headline_markdown,
    headline_table,
    notable_runs,
    overview,
    summarize,
)
from mrmp.core.errors import InputError, Problem
from mrmp.io.report_input import BenchRecord, BenchResults
from mrmp.viz._atomic import write_bytes_atomically
from mrmp.viz.plots import PlotFile, write_report_plots

STYLE = """
body { font-family: -apple-system, "Segoe UI", "DejaVu Sans", Helvetica, Arial, sans-serif; color: #1f2328;
       margin: 0; background: #f6f8fa; line-height: 1.45; }
main { max-width: 1120px; margin: 0 auto; padding: 24px 32px 48px; background: #fff; }
h1 { font-size: 26px; margin: 0 0 4px; }
h2 { font-size: 19px; margin: 32px 0 10px; padding-bottom: 4px; border-bottom: 1px solid #d8dee4; }
.source { color: #59636e; font-size: 13px; margin: 0 0 8px; }
code { font-family: "DejaVu Sans Mono", Menlo, Consolas, monospace; font-size: 12.5px;
       background: #eff2f5; padding: 1px 4px; border-radius: 4px; }
table { border-collapse: collapse; font-size: 13.5px; margin: 8px 0; }
th, td { padding: 5px 10px; border-bottom: 1px solid #e3e7eb; text-align: left; vertical-align: top; }
th { background: #eef1f4; font-weight: 600; white-space: nowrap; }
tbody tr:nth-child(even) { background: #fafbfc; }
tr.policy-start td { border-top: 2px solid #c9d1d9; }
h3 { font-size: 15px; margin: 20px 0 4px; }
td.number, th.number { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
table.facts th { background: none; width: 170px; }
table.compact td { white-space: nowrap; }
nav.contents { font-size: 13px; color: #59636e; margin: 4px 0 8px; }
nav.contents a { margin-right: 12px; }
.good { color: #116329; font-weight: 600; }
.partial { color: #9a6700; font-weight: 600; }
.bad { color: #b91c1c; font-weight: 600; }
.legend { color: #59636e; font-size: 12.5px; max-width: 900px; }
figure { margin: 18px 0 28px; }
figure img { max-width: 100%; height: auto; border: 1px solid #e3e7eb; }
figcaption { color: #59636e; font-size: 12.5px; margin-top: 4px; }
ul.notes li { margin: 3px 0; }
"""

LEGEND = (
    "success: successful runs over all runs (a timeout or an error counts as a failure); "
    "SoC/LB: sum of costs over the sum of the robots' shortest path lengths, mean over the successful runs; "
    "makespan: mean over the successful runs, in ticks; ms/step: wall time per simulated step; "
    "msgs/move: messages sent per robot move; both over the finished runs. "
    "throughput (lifelong runs): goals reached per tick."
)


@dataclass(frozen=True)
class ReportFiles:
    """What :func:`write_report` wrote: the page, the folder of its plots, and the plots."""

    html: Path
    plots_folder: Path
    plots: tuple[PlotFile, ...]


def plots_folder_for(out: str | os.PathLike[str]) -> Path:
    """The folder that holds the PNG files of the report ``out``: ``<stem>_plots`` next to it.

    >>> plots_folder_for("runs/report.html")
    PosixPath('runs/report_plots')
    """
    path = Path(out)
    return path.with_name(f"{path.stem}_plots")


def _join(values: Sequence[object]) -> str:
    return escape(", ".join(str(value) for value in values)) if values else "-"


def _facts(results: BenchResults, facts: BenchOverview) -> str:
    statuses = ", ".join(f"{count} {status}" for status, count in facts.statuses) or "none"
    rows = [
        ("runs", f"{facts.runs} ({escape(statuses)}); {facts.successes} successful"),
        ("maps", _join(facts.maps)),
        ("policies", _join([f"{policy} (central)" if policy in facts.central_policies else policy for policy in facts.policies])),
        ("robots (N)", _join(facts.agents)),
        ("seeds", _join(facts.seeds)),
        *([("instances", _join(facts.instances))] if facts.instances else []),
        ("network faults", _join([faults.label for faults in facts.faults])),
        ("lifelong", _join(["yes" if lifelong else "no" for lifelong in facts.lifelong])),
        ("results file", f"<code>{escape(str(results.path))}</code>"),
    ]
    body = "\n".join(f"<tr><th>{name}</th><td>{value}</td></tr>" for name, value in rows)
    return f'<table class="facts">\n{body}\n</table>'


def _success_class(summary: GroupSummary) -> str:
    if summary.successes == summary.runs:
        return "good"
    return "bad" if summary.successes == 0 else "partial"


def headline_html(summaries: Sequence[GroupSummary]) -> str:
    """The headline table as HTML: one ``<h3>`` and ``<table>`` per map (numbers right-aligned, success coloured).

    The map column is the heading; a line separates one policy's rows from the next.

    >>> from mrmp.bench.aggregate import GroupKey
    >>> from mrmp.io.report_input import FaultSetting
    >>> group = GroupSummary(GroupKey("<m>", "pibt", FaultSetting(), 4), 2, 2, 1, 0, 0, 0, (0, 1),
    ...                      1.5, 12.0, 0.002, 3.0, None)
    >>> lines = headline_html([group]).splitlines()
    >>> print(lines[0])
    <h3>&lt;m&gt;</h3>
    >>> print(lines[-3])
    <tr class="policy-start"><td>pibt</td><td>none</td><td class="number">4</td><td class="number">2</td><td class="number partial">50% (1/2)</td><td class="number">1.500</td><td class="number">12.0</td><td class="number">2.00</td><td class="number">3.00</td></tr>
    """  # noqa: E501
    parts = []
    for map_name in sorted({summary.key.map for summary in summaries}):
        of_map = [summary for summary in summaries if summary.key.map == map_name]
        parts.append(f"<h3>{escape(map_name)}</h3>\n{_map_table(headline_table(of_map), of_map)}")
    return "\n".join(parts)


def _map_table(table: TextTable, summaries: Sequence[GroupSummary]) -> str:
    """One map's rows of the headline table, without the map column."""
    success_column = table.columns.index("success")
    header = "".join(
        f'<th class="number">{escape(name)}</th>' if numeric else f"<th>{escape(name)}</th>"
        for name, numeric in list(zip(table.columns, table.numeric))[1:]
    )
    rows = []
    previous_policy = None
    for summary, row in zip(summaries, table.rows):
        cells = []
        for index, (cell, numeric) in list(enumerate(zip(row, table.numeric)))[1:]:
            classes = ["number"] if numeric else []
            if index == success_column:
                classes.append(_success_class(summary))
            attribute = f' class="{" ".join(classes)}"' if classes else ""
            cells.append(f"<td{attribute}>{escape(cell)}</td>")
        start = ' class="policy-start"' if summary.key.policy != previous_policy else ""
        previous_policy = summary.key.policy
        rows.append(f"<tr{start}>" + "".join(cells) + "</tr>")
    return "<table>\n<thead><tr>" + header + "</tr></thead>\n<tbody>\n" + "\n".join(rows) + "\n</tbody>\n</table>"


@dataclass(frozen=True)
class CompactCell:
    """One policy at one map and N, over every seed and fault setting: runs, successes, timeouts, mean SoC/LB."""

    runs: int
    successes: int
    timeouts: int
    mean_soc_over_lb: float | None

    @property
    def text(self) -> str:
        """``100%, 1.11`` (success, then mean SoC/LB of the successful runs), ``0%``, or ``t/o`` when every run timed out.

        >>> CompactCell(4, 2, 0, 1.234).text, CompactCell(2, 0, 2, None).text, CompactCell(2, 0, 1, None).text
        ('50%, 1.23', 't/o', '0%')
        """
        if self.runs and self.timeouts == self.runs:
            return "t/o"
        share = f"{100 * self.successes / self.runs:.0f}%" if self.runs else "-"
        return share if self.mean_soc_over_lb is None else f"{share}, {self.mean_soc_over_lb:.2f}"


@dataclass(frozen=True)
class CompactTable:
    """The compact table: ``rows`` of ``(map, N)``, ``policies`` as columns, ``cells`` keyed by ``(map, N, policy)``."""

    rows: tuple[tuple[str, int], ...]
    policies: tuple[str, ...]
    cells: dict[tuple[str, int, str], CompactCell]


def compact_table(records: Sequence[BenchRecord]) -> CompactTable:
    """Success and mean SoC/LB of each policy at each map and N, pooled over seeds and fault settings (one-shot runs).

    Maps come in the order the results first name them, N in increasing
    order; decentralized policies first, then the central planners, each in
    the order first run.

    >>> from mrmp.io.report_input import BenchRecord, FaultSetting
    >>> records = [BenchRecord("a", "done", "m", 4, "pibt", 0, FaultSetting(), False, success=True, soc_over_lb=1.5),
    ...            BenchRecord("b", "done", "m", 4, "pibt", 1, FaultSetting(), False, success=False),
    ...            BenchRecord("c", "timeout", "m", 4, "cbs", 0, FaultSetting(), False, kind="centralized")]
    >>> table = compact_table(records)
    >>> table.rows, table.policies, table.cells[("m", 4, "pibt")].text, table.cells[("m", 4, "cbs")].text
    ((('m', 4),), ('pibt', 'cbs'), '50%, 1.50', 't/o')
    """
    one_shot = [record for record in records if not record.lifelong]
    maps = list(dict.fromkeys(record.map for record in one_shot))
    agents = {name: sorted({record.agents for record in one_shot if record.map == name}) for name in maps}
    ordered = list(dict.fromkeys(record.policy for record in one_shot))
    central = {record.policy for record in one_shot if record.kind == "centralized"}
    policies = [policy for policy in ordered if policy not in central] + [policy for policy in ordered if policy in central]
    groups: dict[tuple[str, int, str], list[BenchRecord]] = {}
    for record in one_shot:
        groups.setdefault((record.map, record.agents, record.policy), []).append(record)
    cells = {}
    for key, runs in groups.items():
        successful = [record.soc_over_lb for record in runs if record.succeeded and record.soc_over_lb is not None]
        cells[key] = CompactCell(
            runs=len(runs),
            successes=sum(1 for record in runs if record.succeeded),
            timeouts=sum(1 for record in runs if record.status == "timeout"),
            mean_soc_over_lb=sum(successful) / len(successful) if successful else None,
        )
    rows = tuple((name, count) for name in maps for count in agents[name])
    return CompactTable(rows, tuple(policies), cells)


def compact_html(table: CompactTable) -> str:
    """The compact table as HTML: a line between maps, each cell coloured by its success.

    >>> table = CompactTable((("m", 4),), ("pibt",), {("m", 4, "pibt"): CompactCell(2, 2, 0, 1.25)})
    >>> print(compact_html(table).splitlines()[-3])
    <tr class="policy-start"><td>m</td><td class="number">4</td><td class="good">100%, 1.25</td></tr>
    """
    header = "<th>map</th><th class=\"number\">N</th>" + "".join(f"<th>{escape(policy)}</th>" for policy in table.policies)
    lines = []
    previous = None
    for map_name, agents in table.rows:
        cells = []
        for policy in table.policies:
            cell = table.cells.get((map_name, agents, policy))
            if cell is None:
                cells.append("<td>-</td>")
                continue
            kind = "good" if cell.successes == cell.runs else "bad" if cell.successes == 0 else "partial"
            cells.append(f'<td class="{kind}">{escape(cell.text)}</td>')
        start = ' class="policy-start"' if map_name != previous else ""
        previous = map_name
        lines.append(f'<tr{start}><td>{escape(map_name)}</td><td class="number">{agents}</td>' + "".join(cells) + "</tr>")
    return (
        '<table class="compact">\n<thead><tr>' + header + "</tr></thead>\n<tbody>\n" + "\n".join(lines) + "\n</tbody>\n</table>"
    )


COMPACT_LEGEND = (
    "Each cell: successful runs over all runs of the policy at that map and N, over every seed and fault setting, "
    "then the mean SoC/LB of the successful runs; t/o: every run hit the time limit."
)


def _figure(plot: PlotFile, page_folder: Path) -> str:
    data = base64.b64encode(plot.png).decode("ascii")
    try:
        link = plot.path.resolve().relative_to(page_folder.resolve()).as_posix()
    except ValueError:
        link = plot.path.resolve().as_uri()
    return (
        f'<figure><img src="data:image/png;base64,{data}" alt="{escape(plot.title)}">'
        f'<figcaption>{escape(plot.title)} (file: <a href="{escape(link)}">{escape(link)}</a>)</figcaption></figure>'
    )


def _run_name(record: BenchRecord) -> str:
    instance = f" instance {record.instance}" if record.instance is not None else ""
    return (
        f"{record.map}{instance}, {record.policy}, N={record.agents}, seed {record.seed}, faults {record.faults.label}"
        + (", lifelong" if record.lifelong else "")
        + f" (line {record.line})"
    )


def _notes(results: BenchResults) -> str:
    items = []
    if results.truncated_lines:
        items.append(
            f"The last line of the results file was cut short ({results.truncated_lines} truncated line set aside): "
            "the benchmark was probably interrupted while writing it; that run is not counted."
        )
    if results.replaced_records:
        items.append(
            f"{results.replaced_records} earlier record(s) of runs that were run again (a resumed benchmark) "
            "were replaced by their latest record."
        )
    for record in notable_runs(results.records):
        name = escape(_run_name(record))
        if record.status == "timeout":
            detail = f": {escape(record.error)}" if record.error else ""
            items.append(f'<span class="partial">timeout</span> {name}{detail}')
        elif record.status == "error":
            items.append(f'<span class="bad">error</span> {name}: {escape(record.error or "")}')
        else:
            items.append(f'<span class="bad">{record.collisions} collision(s) found by the referee</span> in {name}')
    if not items:
        return "<p>Every run finished, with no collision found by the referee; no line of the results file was set aside.</p>"
    return '<ul class="notes">\n' + "\n".join(f"<li>{item}</li>" for item in items) + "\n</ul>"


def render_report_html(
    results: BenchResults,
    summaries: Sequence[GroupSummary],
    plots: Sequence[PlotFile],
    page_folder: Path,
    title: str | None = None,
) -> str:
    """The HTML text of a report.

    Parameters
    ----------
    results:
        The records read from ``results.jsonl``.
    summaries:
        Their groups (:func:`mrmp.bench.aggregate.summarize`).
    plots:
        The plots to embed, in order.
    page_folder:
        The folder the page will be written to (plot links are relative to it).
    title:
        The page's title; by default named after the benchmark (its records'
        ``bench``, else its folder).
    """
    facts = overview(results.records)
    if title is None:
        named = ", ".join(facts.benches) if facts.benches else results.path.parent.name or results.path.name
        title = f"mrmp benchmark: {named}"
    figures = "\n".join(_figure(plot, page_folder) for plot in plots) or "<p>No plot: no run finished.</p>"
    table = compact_table(results.records)
    if table.rows:
        summary = f'{compact_html(table)}\n<p class="legend">{escape(COMPACT_LEGEND)}</p>'
    else:
        summary = "<p>No one-shot run: see the plots and every configuration below.</p>"
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{escape(title)}</title>
<style>{STYLE}</style>
</head>
<body>
<main>
<h1>{escape(title)}</h1>
<p class="source">{facts.runs} runs of {len(summaries)} configurations, read from <code>{escape(str(results.path))}</code></p>
<nav class="contents"><a href="#summary">summary</a><a href="#plots">plots</a><a href="#run">what was run</a>\
<a href="#detail">every configuration</a><a href="#notes">notes</a></nav>
<h2 id="summary">Summary</h2>
{summary}
<h2 id="plots">Plots</h2>
{figures}
<h2 id="run">What was run</h2>
{_facts(results, facts)}
<h2 id="detail">Every configuration</h2>
{headline_html(summaries)}
<p class="legend">{escape(LEGEND)}</p>
<h2 id="notes">Notes</h2>
{_notes(results)}
</main>
</body>
</html>
"""


def write_report(
    results: BenchResults,
    out: str | os.PathLike[str],
    title: str | None = None,
    markdown: str | os.PathLike[str] | None = None,
) -> ReportFiles:
    """Write the report page ``out`` and its plots (``<stem>_plots/`` next to it), each file atomically.

    Parameters
    ----------
    results:
        The records read from ``results.jsonl``.
    out:
        The HTML page to write.
    title:
        The page's title (see :func:`render_report_html`).
    markdown:
        When given, also write the headline table as Markdown to this file
        (:func:`mrmp.bench.aggregate.headline_markdown`).

    Returns
    -------
    ReportFiles

    Raises
    ------
    InputError
        If a file cannot be written (naming it).
    """
    page = Path(out)
    folder = plots_folder_for(page)
    summaries = summarize(results.records)
    try:
        plots = tuple(write_report_plots(summaries, folder))
        text = render_report_html(results, summaries, plots, page.parent, title)
        write_bytes_atomically(page, text.encode("utf-8"))
        if markdown is not None:
            write_bytes_atomically(Path(markdown), (headline_markdown(summaries) + "\n").encode("utf-8"))
    except OSError as error:
        where = error.filename if isinstance(error.filename, str) else str(page)
        raise InputError(Problem(where, f"cannot write the report: {error.strerror or error}")) from None
    return ReportFiles(page, folder, plots)
