"""Plots of a benchmark, as PNG files: how each policy scales with the number of robots, and how it bears faults.

For every map, :func:`write_report_plots` draws one figure of small
multiples against N, the number of robots: one row per figure below, one
column per fault setting (so no two lines of a panel differ only by their
faults), one line per policy, each policy with its own colour and marker and
nudged sideways a little (:func:`dodge`), so that policies with the same value,
say all at 100% or all at 0%, show side by side instead of hiding each other:

* success rate (one-shot runs);
* SoC/LB, mean over the successful runs;
* wall time per step, in milliseconds, log scale;
* messages per robot move;
* throughput, goals reached per tick, when the map has lifelong runs.

When a map was run under more than one fault setting, a second figure shows
the success rate of each policy under each setting (over every N), as bars.

matplotlib is imported only when a figure is drawn, and always with its Agg
renderer (no display needed). Every PNG is written to a temporary file in its
folder and then moved into place, so a reader never sees half a picture.

Examples
--------
>>> import tempfile, pathlib
>>> from mrmp.bench.aggregate import summarize
>>> from mrmp.io.report_input import BenchRecord, FaultSetting
>>> records = [BenchRecord(f"r{n}", "done", "empty-8-8", n, "pibt", 0, FaultSetting(), False, success=True,
...                        soc_over_lb=1.1, wall_time_per_step_s=0.001 * n, messages_per_robot_move=2.0)
...            for n in (2, 4, 8)]
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> [plot.path.name for plot in write_report_plots(summarize(records), folder)]
['empty-8-8-vs-n.png']
>>> (folder / "empty-8-8-vs-n.png").read_bytes()[:8] == b"\\x89PNG\\r\\n\\x1a\\n"
True
"""

from __future__ import annotations

import io
import itertools
import os
import re
import textwrap
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mrmp.bench.aggregate import FaultSuccess, GroupSummary, success_by_faults
from mrmp.io.report_input import FaultSetting
from mrmp.viz._atomic import write_bytes_atomically

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

DPI = 100
"""Pixels per inch of the PNG files."""

PANEL_SIZE = (5.4, 3.4)
"""Width and height of one small multiple, in inches."""

MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*", "<", ">")
"""Marker of each policy, in the order of :func:`_policy_colors`."""

DODGE = 0.022
"""Sideways nudge between two policies' points on a log axis of N, in decades."""
LINEAR_DODGE = 0.06
"""Sideways nudge between two policies' points on a linear axis of N, as a share of the smallest gap between two N."""


@dataclass(frozen=True)
class PlotFile:
    """A plot written to disk: its path, a title for a person, and its PNG bytes (for embedding)."""

    path: Path
    title: str
    png: bytes


@dataclass(frozen=True)
class _Metric:
    """One small multiple: what it shows and how its y axis is drawn."""

    title: str
    y_label: str
    value: Callable[[GroupSummary], float | None]
    lifelong: bool = False
    log_y: bool = False
    percent: bool = False
    from_zero: bool = False


METRICS: tuple[_Metric, ...] = (
    _Metric("Success rate", "success (%)", lambda summary: 100 * summary.success_rate, percent=True),
    _Metric("SoC / LB (successful runs)", "SoC / LB", lambda summary: summary.mean_soc_over_lb),
    _Metric(
        "Wall time per step",
        "ms per step (log)",
        lambda summary: None if summary.mean_wall_time_per_step_s is None else 1000 * summary.mean_wall_time_per_step_s,
        log_y=True,
    ),
    _Metric("Messages per robot move", "messages / move", lambda summary: summary.mean_messages_per_robot_move, from_zero=True),
    _Metric("Throughput (lifelong)", "goals per tick", lambda summary: summary.mean_throughput, lifelong=True, from_zero=True),
)
"""The per-N small multiples, in the order they are drawn."""


def file_stem(name: str) -> str:
    """A file-name-safe form of a map name.

    >>> file_stem("gen:random-32x32-p0.2-s3"), file_stem("maps/den 520d")
    ('gen_random-32x32-p0.2-s3', 'maps_den_520d')
    """
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._") or "map"


def _new_figure(width: float, height: float) -> Figure:
    """A figure drawn by the Agg renderer, independent of pyplot's global state."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), dpi=DPI, layout="constrained")
    FigureCanvasAgg(figure)
    return figure


def _png(figure: Figure) -> bytes:
    """The figure as PNG bytes."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=DPI, facecolor="white")
    return buffer.getvalue()


def _policy_colors(summaries: Sequence[GroupSummary]) -> dict[str, Any]:
    """One colour per policy, the same in every figure."""
    from matplotlib import colormaps

    palette = colormaps["tab10"]
    policies = sorted({summary.key.policy for summary in summaries})
    return {policy: palette(index % 10) for index, policy in enumerate(policies)}


def _style_n_axis(axes: Axes, agents: Sequence[int]) -> None:
    """N on the x axis: log scale when it spans a factor of 4 or more; ticks at the values run."""
    from matplotlib.ticker import NullFormatter, NullLocator

    values = sorted(set(agents))
    if values and values[-1] >= 4 * values[0]:
        axes.set_xscale("log")
        axes.xaxis.set_minor_locator(NullLocator())
        axes.xaxis.set_minor_formatter(NullFormatter())
    axes.set_xticks(values, [str(value) for value in values])
    if len(values) > 8:
        axes.tick_params(axis="x", labelrotation=45)
    axes.set_xlabel("robots (N)")


def _plain_log_y(axes: Axes) -> None:
    """A log y axis labelled with plain numbers (0.1, 0.2, 0.5, 1, 2...) rather than powers of ten."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    axes.set_yscale("log")
    axes.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axes.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    axes.yaxis.set_minor_formatter(NullFormatter())


def dodge(agents: Sequence[int], order: int, count: int, log: bool) -> list[float]:
    """The x positions of the ``order``-th of ``count`` policies at ``agents``: nudged apart around each N.

    On a log axis the nudge is a factor (:data:`DODGE` decades per policy);
    on a linear one a share (:data:`LINEAR_DODGE`) of the smallest gap between two values of N.

    >>> [round(x, 2) for x in dodge([10, 100], 0, 3, log=True)]
    [9.51, 95.06]
    >>> dodge([10, 20], 2, 3, log=False)
    [10.6, 20.6]
    """
    shift = order - (count - 1) / 2
    if log:
        return [agents_value * 10 ** (DODGE * shift) for agents_value in agents]
    values = sorted(set(agents))
    gap = min((b - a for a, b in itertools.pairwise(values)), default=1)
    return [agents_value + shift * gap * LINEAR_DODGE for agents_value in agents]


def _n_is_log(agents: Sequence[int]) -> bool:
    values = sorted(set(agents))
    return bool(values) and values[-1] >= 4 * values[0]


def _draw_panel(
    axes: Axes,
    metric: _Metric,
    chosen: Sequence[GroupSummary],
    faults: FaultSetting,
    colors: dict[str, Any],
    handles: dict[str, Any],
    *,
    titled_faults: bool,
    labelled: bool,
) -> None:
    """One small multiple: ``metric`` against N under ``faults``, a dodged line per policy (its handle kept in ``handles``)."""
    policies = list(colors)
    of_setting = [summary for summary in chosen if summary.key.faults == faults]
    all_agents = [summary.key.agents for summary in chosen]
    log_x = _n_is_log(all_agents)
    series: dict[str, list[tuple[int, float]]] = {}
    for summary in of_setting:
        value = metric.value(summary)
        if value is not None:
            series.setdefault(summary.key.policy, []).append((summary.key.agents, value))
    for policy, points in sorted(series.items(), key=lambda item: policies.index(item[0])):
        points.sort()
        order = policies.index(policy)
        (line,) = axes.plot(
            dodge([agents for agents, _ in points], order, len(policies), log_x),
            [value for _, value in points],
            marker=MARKERS[order % len(MARKERS)],
            markersize=6.5,
            markeredgecolor="white",
            markeredgewidth=0.8,
            linewidth=1.6,
            color=colors[policy],
            label=policy,
        )
        handles.setdefault(policy, line)
    _style_n_axis(axes, all_agents)
    title = f"{metric.title} · faults: {faults.label}" if titled_faults else metric.title
    axes.set_title(title, fontsize=10.5)
    if labelled:
        axes.set_ylabel(metric.y_label)
    axes.grid(True, which="major", alpha=0.3)
    if metric.percent:
        axes.set_ylim(-6, 106)
    elif metric.log_y:
        _plain_log_y(axes)


def _draw_per_n(map_name: str, summaries: Sequence[GroupSummary], colors: dict[str, Any]) -> Figure | None:
    """The small multiples of one map (metrics by rows, fault settings by columns), or None when it has nothing to draw."""
    panels = []
    for metric in METRICS:
        chosen = [summary for summary in summaries if summary.key.lifelong == metric.lifelong]
        if any(metric.value(summary) is not None for summary in chosen):
            panels.append((metric, chosen))
    if not panels:
        return None
    settings = sorted({summary.key.faults for summary in summaries})
    policies = list(colors)
    if len(settings) == 1:  # metrics two by two
        columns, rows = (2 if len(panels) > 1 else 1), (len(panels) + 1) // 2
        places = [(metric, chosen, settings[0], index // 2, index % 2) for index, (metric, chosen) in enumerate(panels)]
    else:  # a row per metric, a column per fault setting
        columns, rows = len(settings), len(panels)
        places = [
            (metric, chosen, faults, row, column)
            for row, (metric, chosen) in enumerate(panels)
            for column, faults in enumerate(settings)
        ]
    figure = _new_figure(PANEL_SIZE[0] * columns, PANEL_SIZE[1] * rows + 0.9)
    figure.suptitle(f"{map_name}: scaling with the number of robots", fontsize=13, fontweight="bold")
    handles: dict[str, Any] = {}
    row_axes: dict[int, Axes] = {}
    drawn: list[tuple[_Metric, Axes]] = []
    for metric, chosen, faults, row, column in places:
        shared = row_axes.get(row) if len(settings) > 1 else None
        axes = figure.add_subplot(rows, columns, row * columns + column + 1, sharey=shared)
        row_axes.setdefault(row, axes)
        drawn.append((metric, axes))
        _draw_panel(
            axes, metric, chosen, faults, colors, handles, titled_faults=len(settings) > 1, labelled=column == 0
        )
    for metric, axes in drawn:
        if metric.from_zero:  # once every panel is drawn: an axis shared along a row fits them all
            axes.autoscale(axis="y")
            axes.set_ylim(bottom=0)
    ordered = [policy for policy in policies if policy in handles]
    figure.legend(
        [handles[policy] for policy in ordered],
        ordered,
        loc="outside lower center",
        ncols=min(len(ordered), 7),
        frameon=False,
    )
    return figure


def _draw_faults(map_name: str, pooled: Sequence[FaultSuccess], colors: dict[str, Any]) -> Figure:
    """Grouped bars: one group per fault setting, one bar per policy, height the success rate."""
    settings = sorted({row.faults for row in pooled})
    policies = sorted({row.policy for row in pooled})
    figure = _new_figure(min(2 * PANEL_SIZE[0], max(7.0, 2.0 + 0.9 * len(settings) * len(policies))), 4.6)
    axes = figure.add_subplot(1, 1, 1)
    width = 0.8 / len(policies)
    for position, policy in enumerate(policies):
        rows = {row.faults: row for row in pooled if row.policy == policy}
        xs = [index + (position - (len(policies) - 1) / 2) * width for index, faults in enumerate(settings) if faults in rows]
        chosen = [rows[faults] for faults in settings if faults in rows]
        bars = axes.bar(xs, [100 * row.success_rate for row in chosen], width * 0.92, color=colors[policy], label=policy)
        axes.bar_label(bars, labels=[f"{row.successes}/{row.runs}" for row in chosen], fontsize=8, padding=2)
    axes.set_xticks(range(len(settings)), [textwrap.fill(faults.label, 18) for faults in settings])
    axes.set_ylim(0, 108)
    axes.set_ylabel("success (%)")
    axes.set_xlabel("network faults")
    axes.grid(True, axis="y", alpha=0.3)
    axes.set_title(f"{map_name}: success under network faults (all N pooled)", fontsize=12, fontweight="bold")
    figure.legend(loc="outside lower center", fontsize=9, frameon=False, ncols=min(len(policies), 6))
    return figure


def write_report_plots(summaries: Sequence[GroupSummary], folder: str | os.PathLike[str]) -> list[PlotFile]:
    """Draw every plot of a benchmark and write them as PNG files into ``folder``.

    Parameters
    ----------
    summaries:
        The configurations of the benchmark (:func:`mrmp.bench.aggregate.summarize`).
    folder:
        Where the PNG files go (created if missing): ``<map>-vs-n.png`` for
        each map, and ``<map>-faults.png`` for each map run under more than
        one fault setting.

    Returns
    -------
    list of PlotFile
        The plots written, map by map.
    """
    target = Path(folder)
    colors = _policy_colors(summaries)
    pooled = success_by_faults(summaries)
    plots: list[PlotFile] = []
    used: set[str] = set()
    for map_name in sorted({summary.key.map for summary in summaries}):
        stem = file_stem(map_name)
        while stem in used:
            stem += "_"
        used.add(stem)
        of_map = [summary for summary in summaries if summary.key.map == map_name]
        figure = _draw_per_n(map_name, of_map, colors)
        if figure is not None:
            plots.append(_save(figure, target / f"{stem}-vs-n.png", f"{map_name}: scaling with the number of robots"))
        map_pooled = [row for row in pooled if row.map == map_name]
        if len({row.faults for row in map_pooled}) > 1:
            figure = _draw_faults(map_name, map_pooled, colors)
            plots.append(_save(figure, target / f"{stem}-faults.png", f"{map_name}: success under network faults"))
    return plots


def _save(figure: Figure, path: Path, title: str) -> PlotFile:
    png = _png(figure)
    write_bytes_atomically(path, png)
    return PlotFile(path, title, png)
