"""Drawing quality that fits the machine: what the 3-D view costs per frame.

A CPU rasteriser (Mesa's llvmpipe or softpipe) pays for every pixel it shades, and at 1280x720 the
view's pixels are nearly all of a frame's time: 4x MSAA shades up to four samples per pixel and the
ball shadows read the sun's grid in every plane pixel. So on a software renderer the viewer starts at
``low``: no MSAA, shadows that read at most a few balls per pixel, and the 3-D view drawn at a lower
resolution and scaled up to the window (the HUD and labels stay sharp, drawn at full size). A real GPU
starts at ``high``: everything at full size. ``ballpit view --quality`` chooses, and F3 switches live.
No GL here: the window reads GL_RENDERER and asks ``choose``.
"""

from __future__ import annotations

from dataclasses import dataclass

SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "swrast", "software rasterizer")


@dataclass(frozen=True)
class Quality:
    """How the 3-D view is drawn: MSAA ``samples``, balls read per shadow-grid cell (``shadow_limit``;
    0: no shadows) and the view's resolution as a fraction of the window's (``scale``)."""

    name: str
    samples: int
    shadow_limit: int
    scale: float

    def describe(self) -> str:
        msaa = f"{self.samples}x MSAA" if self.samples else "no MSAA"
        limit = self.shadow_limit
        shadows = f"shadows {limit} balls/px" if limit else "no shadows"
        return f"{self.name}: {msaa}, {shadows}, view {self.scale:.0%}"


QUALITIES: dict[str, Quality] = {
    "high": Quality("high", samples=4, shadow_limit=12, scale=1.0),
    "low": Quality("low", samples=0, shadow_limit=3, scale=0.5),
}
CHOICES = ("auto", *QUALITIES)


def is_software(renderer: str) -> bool:
    """Whether GL_RENDERER names a CPU rasteriser."""
    name = renderer.lower()
    return any(word in name for word in SOFTWARE_RENDERERS)


def choose(option: str, renderer: str) -> Quality:
    """The quality for ``option`` ("auto", "low" or "high"): auto is low on a software renderer."""
    if option == "auto":
        option = "low" if is_software(renderer) else "high"
    if option not in QUALITIES:
        raise ValueError(f"quality must be one of {', '.join(CHOICES)}, got {option!r}")
    return QUALITIES[option]


def other(quality: Quality) -> Quality:
    """F3: the other level."""
    return QUALITIES["high" if quality.name == "low" else "low"]
