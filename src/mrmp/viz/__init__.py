"""Pictures of runs: animated GIF (Pillow) and animated SVG (SMIL).

This is the only layer that imports Pillow. Both renderers share their
geometry, colours and motion through :mod:`mrmp.viz.layout`; the picture is
drawn NORTH up and EAST to the right.

* :func:`write_animation` picks the format from the file's suffix.
* :func:`write_gif` writes an animated GIF.
* :func:`write_svg` writes an animated SVG that plays in a browser.
"""

from mrmp.viz.animate import write_animation
from mrmp.viz.gif import write_gif
from mrmp.viz.svg import write_svg

__all__ = ["write_animation", "write_gif", "write_svg"]
