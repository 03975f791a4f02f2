"""mrmp report end to end: files written, table printed, exit 2 with one line per problem on bad input."""

import json

import pytest
from PIL import Image
from report_fixtures import make_record, unfinished, write_jsonl
from typer.testing import CliRunner

from mrmp.cli import app

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(arg) for arg in args])


def test_report_of_a_bench_folder_writes_page_and_plots_and_prints_the_table(tmp_path, simulated_records):
    write_jsonl(tmp_path / "bench" / "results.jsonl", simulated_records)
    out = tmp_path / "site" / "report.html"
    result = invoke("report", tmp_path / "bench", "--out", out)
    assert result.exit_code == 0, result.output
    assert f"report written to {out}" in result.output
    assert f"2 plots written to {tmp_path / 'site' / 'report_plots'}" in result.output
    assert "18 runs from" in result.output and "empty-8-8" in result.output
    assert "success" in result.output and "SoC/LB" in result.output and "msgs/move" in result.output
    rows = [line.split() for line in result.output.splitlines()]
    assert ["pibt", "none", "no", "2", "2", "100%", "(2/2)"] in [row[:7] for row in rows]
    page = out.read_text()
    assert page.count("data:image/png;base64,") == 2
    for png in (tmp_path / "site" / "report_plots").iterdir():
        with Image.open(png) as image:
            assert image.format == "PNG"


def test_report_reads_a_jsonl_path_and_notes_a_truncated_line_and_unfinished_runs(tmp_path):
    path = write_jsonl(
        tmp_path / "results.jsonl",
        [make_record(run_id="a"), unfinished("timeout", "time limit", run_id="b", seed=1)],
        tail=json.dumps(make_record(run_id="c"))[:40],
    )
    result = invoke("report", path, "--out", tmp_path / "r.html")
    assert result.exit_code == 0, result.output
    assert "was cut short" in result.output and "1 runs timed out or failed" in result.output
    assert "50% (1/2)" in result.output
    assert (tmp_path / "r.html").exists() and (tmp_path / "r_plots" / "empty-8-8-vs-n.png").exists()


def test_a_malformed_line_exits_2_with_its_file_and_line(tmp_path):
    path = tmp_path / "results.jsonl"
    path.write_text(json.dumps(make_record(run_id="a")) + "\n{oops\n" + json.dumps(make_record(run_id="b")) + "\n")
    result = invoke("report", tmp_path, "--out", tmp_path / "report.html")
    assert result.exit_code == 2
    assert f"error: {path}:2: not valid JSON" in result.output
    assert "Traceback" not in result.output
    assert not (tmp_path / "report.html").exists()


def test_a_missing_folder_or_an_empty_file_exits_2(tmp_path):
    result = invoke("report", tmp_path / "nowhere", "--out", tmp_path / "report.html")
    assert result.exit_code == 2 and "nowhere: file not found" in result.output
    (tmp_path / "results.jsonl").write_text("")
    result = invoke("report", tmp_path, "--out", tmp_path / "report.html")
    assert result.exit_code == 2 and "no run record in the file" in result.output
    assert "Traceback" not in result.output


def test_an_unwritable_out_exits_2(tmp_path):
    write_jsonl(tmp_path / "results.jsonl", [make_record()])
    (tmp_path / "taken.html").mkdir()
    result = invoke("report", tmp_path, "--out", tmp_path / "taken.html")
    assert result.exit_code == 2 and "cannot write the report" in result.output
    assert "Traceback" not in result.output


@pytest.mark.slow
def test_markdown_option_writes_the_headline_table(tmp_path):
    write_jsonl(tmp_path / "results.jsonl", [make_record(run_id="a"), make_record(run_id="b", seed=1, success=False)])
    result = invoke("report", tmp_path, "--out", tmp_path / "report.html", "--markdown", tmp_path / "table.md")
    assert result.exit_code == 0, result.output
    assert f"headline table (Markdown) written to {tmp_path / 'table.md'}" in result.output
    assert (tmp_path / "table.md").read_text().splitlines() == [
        "| map | policy | faults | N | runs | success | SoC/LB | makespan | ms/step | msgs/move |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|",
        "| empty-8-8 | pibt | none | 4 | 2 | 50% (1/2) | 1.200 | 10.0 | 5.00 | 4.00 |",
    ]
