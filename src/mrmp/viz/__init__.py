"""Pictures of runs: animated GIF and MP4 (Pillow, ffmpeg), animated SVG (SMIL), a live terminal view.

This is the only layer that imports Pillow. The renderers share their
geometry, colours and motion through :mod:`mrmp.viz.layout`; the picture is
drawn NORTH up and EAST to the right.

* :func:`write_animation` picks the format from the file's suffix
  (:func:`animation_problem` checks a path first).
* :func:`write_gif` writes an animated GIF.
* :func:`write_svg` writes an animated SVG that plays in a browser.
* :func:`write_mp4` writes an H.264 video with ffmpeg.
* :mod:`mrmp.viz.terminal` draws a run in the terminal as it goes.
"""

from mrmp.viz.animate import animation_problem, write_animation
from mrmp.viz.gif import write_gif
from mrmp.viz.mp4 import write_mp4
from mrmp.viz.svg import write_svg

__all__ = ["animation_problem", "write_animation", "write_gif", "write_mp4", "write_svg"]
