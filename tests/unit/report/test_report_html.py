"""The HTML report: the table rows, the embedded plots (also on disk), the notes, and escaping."""

import base64
import re

import pytest
from report_fixtures import NO_FAULTS, make_record, unfinished, write_jsonl

from mrmp.bench.aggregate import summarize
from mrmp.io.report_input import read_bench_results
from mrmp.viz.report_html import headline_html, write_report


@pytest.mark.slow
def test_report_of_real_runs_has_every_row_and_embeds_every_plot(tmp_path, simulated_records):
    results = read_bench_results(write_jsonl(tmp_path / "bench" / "results.jsonl", simulated_records))
    files = write_report(results, tmp_path / "out" / "report.html")
    page = files.html.read_text(encoding="utf-8")
    summaries = summarize(results.records)
    body = page.split('<h2 id="detail">Every configuration</h2>')[1].split("</table>")[0]
    assert body.startswith("\n<h3>empty-8-8</h3>\n<table>")
    rows = re.findall(r"<tr(?: class=\"policy-start\")?><td>(astar|pibt)</td>", body)
    assert len(rows) == len(summaries) == 9  # 2 policies x 2 N x 2 losses, and the lifelong runs
    assert '<tr class="policy-start"><td>pibt</td><td>none</td><td>no</td><td class="number">2</td><td class="number">2</td>' in body
    assert '<tr><td>pibt</td><td>none</td><td>yes</td><td class="number">3</td><td class="number">2</td>' in body
    assert "<title>mrmp benchmark: bench</title>" in page
    assert files.plots_folder == tmp_path / "out" / "report_plots"
    embedded = re.findall(r'src="data:image/png;base64,([A-Za-z0-9+/=]+)"', page)
    assert len(embedded) == len(files.plots) == 2
    for data, plot in zip(embedded, files.plots):
        assert base64.b64decode(data) == plot.path.read_bytes()
        assert plot.path.parent == files.plots_folder
        assert f'href="report_plots/{plot.path.name}"' in page
    assert "<script" not in page.lower() and "http://" not in page and "https://" not in page
    for name, value in [
        ("runs", "18 (18 done); 16 successful"),  # astar, 4 robots, seed 1 deadlocks, with and without loss
        ("maps", "empty-8-8"),
        ("policies", "astar, pibt"),
        ("robots (N)", "2, 3, 4"),
        ("seeds", "0, 1"),
        ("network faults", "none, loss 0.3"),
        ("lifelong", "no, yes"),
    ]:
        assert f"<tr><th>{name}</th><td>{value}</td></tr>" in page


def test_notes_name_timeouts_errors_collisions_and_a_truncated_line(tmp_path):
    records = [
        make_record(run_id="a", seed=0),
        make_record(run_id="b", seed=1, success=False, collisions=2),
        unfinished("timeout", "time limit 60 s", run_id="c", seed=2),
        unfinished("error", "planner crashed", run_id="d", seed=3, agents=8),
    ]
    results = read_bench_results(write_jsonl(tmp_path / "results.jsonl", records, tail='{"format": "mrmp-bench-1", "run'))
    page = write_report(results, tmp_path / "report.html").html.read_text()
    notes = page.split('<h2 id="notes">Notes</h2>')[1]
    assert "1 truncated line set aside" in notes
    assert "timeout</span> empty-8-8, pibt, N=4, seed 2, faults none (line 3): time limit 60 s" in notes
    assert "error</span> empty-8-8, pibt, N=8, seed 3, faults none (line 4): planner crashed" in notes
    assert "2 collision(s) found by the referee</span> in empty-8-8, pibt, N=4, seed 1" in notes
    assert "2 done, 1 timeout, 1 error" in page


def test_a_clean_benchmark_says_so_in_its_notes(tmp_path):
    results = read_bench_results(write_jsonl(tmp_path / "results.jsonl", [make_record()]))
    page = write_report(results, tmp_path / "report.html", title="Nightly").html.read_text()
    assert "<tr><th>policies</th><td>pibt</td></tr>" in page
    assert "<h1>Nightly</h1>" in page
    assert "Every run finished, with no collision found by the referee" in page


def test_every_string_from_the_results_is_escaped(tmp_path):
    hostile = '<script>alert("x")</script>'
    records = [make_record(map=hostile, policy="<b>p</b>"), unfinished("error", "<img src=x onerror=y>", run_id="e")]
    results = read_bench_results(write_jsonl(tmp_path / "results.jsonl", records))
    page = write_report(results, tmp_path / "report.html").html.read_text()
    assert "<script" not in page and "<b>p</b>" not in page and "<img src=x" not in page
    assert "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;" in page and "&lt;img src=x onerror=y&gt;" in page


def test_headline_html_colours_success_and_aligns_numbers(tmp_path):
    records = [make_record(run_id="a", agents=2), make_record(run_id="b", agents=4, success=False, soc_over_lb=None)]
    results = read_bench_results(write_jsonl(tmp_path / "results.jsonl", records))
    table = headline_html(summarize(results.records))
    assert '<th class="number">SoC/LB</th>' in table
    assert '<td class="number good">100% (1/1)</td>' in table and '<td class="number bad">0% (0/1)</td>' in table
    assert table.count("<tr") == 3 and table.count('<tr class="policy-start">') == 1


def test_an_unwritable_report_is_an_input_error(tmp_path):
    import pytest

    from mrmp.core.errors import InputError

    results = read_bench_results(write_jsonl(tmp_path / "results.jsonl", [make_record()]))
    (tmp_path / "report.html").mkdir()
    with pytest.raises(InputError, match="cannot write the report"):
        write_report(results, tmp_path / "report.html")


def test_the_page_leads_with_the_compact_table_and_the_plots(tmp_path, simulated_records):
    results = read_bench_results(write_jsonl(tmp_path / "bench" / "results.jsonl", simulated_records))
    page = write_report(results, tmp_path / "report.html").html.read_text(encoding="utf-8")
    headings = re.findall(r'<h2 id="([a-z]+)">', page)
    assert headings == ["summary", "plots", "run", "detail", "notes"]
    first_plot = page.index('src="data:image/png')
    assert first_plot < page.index('<h2 id="detail">'), "the plots come before the detail"
    assert page[: page.index('<h2 id="plots">')].count("<tr") < 10, "few rows before the first plot"
    summary = page.split('<h2 id="summary">Summary</h2>')[1].split("</table>")[0]
    first_run = list(dict.fromkeys(record["policy"] for record in simulated_records))
    columns = "".join(f"<th>{policy}</th>" for policy in first_run)
    assert f"<th>map</th><th class=\"number\">N</th>{columns}</tr>" in summary, "policies in the order first run"
    rows = re.findall(r"<tr(?: class=\"policy-start\")?><td>empty-8-8</td><td class=\"number\">(\d+)</td>", summary)
    assert rows == ["2", "4"], "one row per map and N of the one-shot runs"


def test_compact_cells_pool_seeds_and_faults(tmp_path):
    from mrmp.io.report_input import FaultSetting
    from mrmp.viz.report_html import compact_table

    lossy = {**NO_FAULTS, "loss": 0.3}
    records = [
        make_record(run_id="a", seed=0, soc_over_lb=1.2),
        make_record(run_id="b", seed=1, soc_over_lb=1.4),
        make_record(run_id="c", seed=0, faults=lossy, success=False, soc_over_lb=None),
        unfinished("timeout", "time limit", run_id="d", seed=1, faults=lossy),
        unfinished("timeout", "time limit", run_id="e", seed=0, policy="cbs", kind="centralized"),
    ]
    results = read_bench_results(write_jsonl(tmp_path / "results.jsonl", records))
    table = compact_table(results.records)
    assert table.policies == ("pibt", "cbs"), "central planners after the robots' own policies"
    cell = table.cells[("empty-8-8", 4, "pibt")]
    assert (cell.runs, cell.successes, cell.timeouts) == (4, 2, 1)
    assert cell.text == "50%, 1.30"
    assert table.cells[("empty-8-8", 4, "cbs")].text == "t/o"
    assert len({record.faults for record in results.records}) == 2 and FaultSetting() in {r.faults for r in results.records}
