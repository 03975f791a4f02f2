"""Benchmark plots: PNG files that open, with real content, written atomically."""

from PIL import Image
from report_fixtures import make_record

from mrmp.bench.aggregate import summarize
from mrmp.io.report_input import record_from_dict
from mrmp.viz.plots import DPI, PANEL_SIZE, file_stem, write_report_plots

TAB10_BLUE, TAB10_ORANGE = (31, 119, 180), (255, 127, 14)


def typed(records):
    return [record_from_dict(record, line) for line, record in enumerate(records, start=1)]


def colours_of(path):
    with Image.open(path) as image:
        image.load()
        return image.format, image.size, {colour for _, colour in image.convert("RGB").getcolors(1 << 20)}


def test_plots_of_real_runs_are_valid_pngs_with_content(tmp_path, simulated_records):
    plots = write_report_plots(summarize(typed(simulated_records)), tmp_path / "plots")
    assert [plot.path.name for plot in plots] == ["empty-8-8-vs-n.png", "empty-8-8-faults.png"]
    for plot in plots:
        assert plot.path.read_bytes() == plot.png
        assert plot.path.stat().st_size > 20_000
        image_format, (width, height), colours = colours_of(plot.path)
        assert image_format == "PNG" and width >= 600 and height >= 400
        assert len(colours) > 100  # lines, text, antialiasing: not a blank canvas
        assert TAB10_BLUE in colours and TAB10_ORANGE in colours  # the two policies' colours
    assert sorted(path.name for path in (tmp_path / "plots").iterdir()) == ["empty-8-8-faults.png", "empty-8-8-vs-n.png"]


def test_lifelong_runs_add_a_throughput_panel(tmp_path, simulated_records):
    one_shot = [record for record in simulated_records if not record["lifelong"]]
    [with_lifelong] = [p for p in write_report_plots(summarize(typed(simulated_records)), tmp_path / "a") if "vs-n" in p.path.name]
    [without] = [p for p in write_report_plots(summarize(typed(one_shot)), tmp_path / "b") if "vs-n" in p.path.name]
    rows_height = PANEL_SIZE[1] * DPI
    _, (_, tall), _ = colours_of(with_lifelong.path)
    _, (_, short), _ = colours_of(without.path)
    assert tall - short == round(rows_height)  # 5 panels in 3 rows against 4 panels in 2 rows


def test_one_fault_setting_draws_no_fault_chart_and_one_figure_per_map(tmp_path):
    records = typed(
        [
            make_record(run_id=f"{name}{agents}", map=name, agents=agents, seed=seed)
            for name in ("gen:random-8x8-p0.1-s1", "warehouse")
            for agents in (2, 4, 8)
            for seed in (0, 1)
        ]
    )
    plots = write_report_plots(summarize(records), tmp_path)
    assert [plot.path.name for plot in plots] == ["gen_random-8x8-p0.1-s1-vs-n.png", "warehouse-vs-n.png"]
    assert [plot.title for plot in plots] == [
        "gen:random-8x8-p0.1-s1: scaling with the number of robots",
        "warehouse: scaling with the number of robots",
    ]


def test_map_names_that_clash_as_file_names_get_distinct_files(tmp_path):
    plots = write_report_plots(summarize(typed([make_record(run_id="a", map="a:b"), make_record(run_id="b", map="a/b")])), tmp_path)
    assert len({plot.path for plot in plots}) == 2 and all(plot.path.exists() for plot in plots)


def test_plots_replace_old_files_and_leave_no_temporary_file(tmp_path):
    old = tmp_path / "m-vs-n.png"
    old.write_bytes(b"old")
    [plot] = write_report_plots(summarize(typed([make_record(map="m")])), tmp_path)
    assert plot.path == old and old.read_bytes()[:4] == b"\x89PNG"
    assert [path.name for path in tmp_path.iterdir()] == ["m-vs-n.png"]


def test_file_stem():
    assert file_stem("random-32-32-20") == "random-32-32-20"
    assert file_stem("../etc/passwd") == "etc_passwd"
    assert file_stem("???") == "map"
