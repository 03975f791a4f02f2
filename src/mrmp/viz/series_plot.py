"""One quantity against the number of robots, one line per method, as a PNG file.

The plots of a benchmark report (:mod:`mrmp.viz.plots`) are drawn from a bench's
results; this draws any such series given as numbers, for the scripts in
``bench/`` that measure something of their own (``bench/chapter5.py`` draws one
figure per claim of the thesis's chapter 5 with it). Methods keep their own
colour and marker and are nudged sideways a little, as in the report, so equal
values show side by side.

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> series = {"pibt": [(2, 0.1), (10, 1.1), (100, 6.0)], "lacam": [(2, 5.1), (10, 27.1), (100, 247.4)]}
>>> plot = write_series_plot(folder / "speed.png", "Messages per move", "datagrams / move (log)", series, log_y=True)
>>> plot.path.name, plot.png[:8] == b"\\x89PNG\\r\\n\\x1a\\n", plot.path.read_bytes() == plot.png
('speed.png', True, True)
>>> write_series_plot(folder / "empty.png", "Nothing", "y", {})
Traceback (most recent call last):
    ...
ValueError: Nothing: no series to draw
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

from mrmp.viz.plots import MARKERS, PANEL_SIZE, PlotFile, _n_is_log, _new_figure, _plain_log_y, _save, _style_n_axis, dodge

__all__ = ["write_series_plot"]


def write_series_plot(
    path: str | os.PathLike[str],
    title: str,
    y_label: str,
    series: Mapping[str, Sequence[tuple[int, float]]],
    *,
    log_y: bool = False,
    percent: bool = False,
) -> PlotFile:
    """Draw each method's ``(robots, value)`` points against N and write the PNG to ``path`` (atomically).

    Parameters
    ----------
    path:
        The PNG file to write.
    title, y_label:
        The figure's title and its y axis's label.
    series:
        For each method, its points ``(number of robots, value)``; a method
        with no point is left out of the legend.
    log_y:
        A log y axis (every value must be positive), labelled with plain numbers.
    percent:
        The values are shares from 0 to 100: the y axis runs from 0 to 100.

    Raises
    ------
    ValueError
        If no method has a point, or ``log_y`` is asked with a value at or below zero.
    """
    drawn = {method: sorted(points) for method, points in series.items() if points}
    if not drawn:
        raise ValueError(f"{title}: no series to draw")
    if log_y and any(value <= 0 for points in drawn.values() for _, value in points):
        raise ValueError(f"{title}: a log axis needs positive values")
    from matplotlib import colormaps

    palette = colormaps["tab10"]
    figure = _new_figure(*PANEL_SIZE)
    axes = figure.add_subplot()
    every_n = [robots for points in drawn.values() for robots, _ in points]
    log_n = _n_is_log(every_n)
    for order, (method, points) in enumerate(drawn.items()):
        robots = [count for count, _ in points]
        axes.plot(
            dodge(robots, order, len(drawn), log_n),
            [value for _, value in points],
            label=method,
            color=palette(order % 10),
            marker=MARKERS[order % len(MARKERS)],
            linewidth=1.4,
            markersize=5,
        )
    _style_n_axis(axes, every_n)
    if log_y:
        _plain_log_y(axes)
    if percent:
        axes.set_ylim(-3, 103)
    axes.set_ylabel(y_label)
    axes.set_title(title)
    axes.grid(True, alpha=0.3)
    axes.legend(fontsize="small")
    return _save(figure, Path(path), title)
