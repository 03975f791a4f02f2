"""Looking at drawn pictures in the visualization tests: colours near a point."""

from __future__ import annotations

from PIL import Image

Colour = tuple[int, int, int]


def close(pixel: Colour, colour: Colour, tolerance: int = 24) -> bool:
    """Whether ``pixel`` is within ``tolerance`` of ``colour`` in every channel."""
    return all(abs(a - b) <= tolerance for a, b in zip(pixel, colour))


def share_near(
    image: Image.Image, centre: tuple[float, float], radius: float, colour: Colour, tolerance: int = 24
) -> float:
    """Share of the pixels within ``radius`` of ``centre`` that have about ``colour`` (:func:`close`)."""
    cx, cy = centre
    hits = total = 0
    for x in range(int(cx - radius), int(cx + radius) + 1):
        for y in range(int(cy - radius), int(cy + radius) + 1):
            if (x - cx) ** 2 + (y - cy) ** 2 <= radius**2:
                total += 1
                hits += close(image.getpixel((x, y)), colour, tolerance)
    return hits / total
