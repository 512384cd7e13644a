"""Drawing quality (quality.py): software GL starts low, a GPU high; the low view is drawn smaller and
stretched over the frame (framebuffer.WindowView) and still shows the same picture."""

from __future__ import annotations

import numpy as np
import pytest

from ballpit.viewer.quality import QUALITIES, choose, is_software, other

from .conftest import line_of_balls


@pytest.mark.parametrize(
    "renderer, expected",
    [
        ("llvmpipe (LLVM 15.0.6, 256 bits)", "low"),
        ("softpipe", "low"),
        ("Software Rasterizer", "low"),
        ("NVIDIA GeForce RTX 3060/PCIe/SSE2", "high"),
        ("AMD Radeon RX 6700 XT (radeonsi, navi22, LLVM 15.0.7, DRM 3.49)", "high"),
        ("Mesa Intel(R) UHD Graphics 620 (KBL GT2)", "high"),
    ],
)
def test_auto_is_low_on_a_software_renderer_and_high_on_a_gpu(renderer, expected):
    assert choose("auto", renderer).name == expected
    assert is_software(renderer) == (expected == "low")


def test_low_and_high_are_what_they_say_and_f3_switches_between_them():
    low, high = QUALITIES["low"], QUALITIES["high"]
    assert low.samples == 0 and 0 < low.shadow_limit < high.shadow_limit and low.scale < 1.0
    assert high.samples == 4 and high.scale == 1.0
    assert choose("high", "llvmpipe") is high and choose("low", "NVIDIA") is low
    assert other(low) is high and other(high) is low
    with pytest.raises(ValueError, match="quality must be one of auto, high, low"):
        choose("ultra", "llvmpipe")


def test_the_half_resolution_view_stretched_over_the_frame_shows_the_same_picture(offscreen):
    from OpenGL import GL

    from ballpit.viewer.camera import Camera
    from ballpit.viewer.framebuffer import WindowView
    from ballpit.viewer.simulation import Simulation

    sim = Simulation(line_of_balls(5))
    camera = Camera.looking_at((0, 4, 12), (0, 3, 0))
    full = offscreen.render(sim, camera)
    view = WindowView(samples=0, scale=0.5)
    try:
        w, h = offscreen.width, offscreen.height
        drawn = view.begin(w, h, offscreen.target.fbo)
        assert drawn == (w // 2, h // 2)
        offscreen.renderer.draw(camera, *drawn)
        view.finish(w, h, offscreen.target.fbo)
        stretched = offscreen.target.read()
    finally:
        view.delete()
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, 0)
    assert stretched.shape == full.shape
    difference = np.abs(stretched.astype(int) - full.astype(int)).mean(axis=-1)
    assert difference.mean() < 6.0  # the same picture, coarser at the edges
    background = np.array(full[0, 0], dtype=int)
    balls = np.abs(full.astype(int) - background).sum(axis=-1) > 60
    assert balls.any() and (np.abs(stretched.astype(int) - background).sum(axis=-1) > 60).any()
    # each texel of the half-size view covers its 2x2 block of the frame, unblended (nearest)
    blocks = stretched.reshape(h // 2, 2, w // 2, 2, 3).astype(int)
    assert (blocks == blocks[:, :1, :, :1]).all()
    assert len(np.unique(blocks[:, 0, :, 0].reshape(-1, 3), axis=0)) > 20  # not a flat image


@pytest.mark.parametrize("samples, scale", [(0, 0.5), (0, 1.0), (4, 1.0), (4, 0.5)])
def test_the_view_right_of_the_panel_is_the_same_picture_and_nothing_is_drawn_under_it(
    offscreen, samples, scale
):
    """The panel is opaque, so the view is not shaded under it (WindowView.begin's ``left``): every
    pixel right of the panel's edge is the one the whole view draws, and the strip under it is cleared."""
    from OpenGL import GL

    from ballpit.viewer.camera import Camera
    from ballpit.viewer.framebuffer import WindowView
    from ballpit.viewer.simulation import Simulation

    sim = Simulation(line_of_balls(5))
    camera = Camera.looking_at((-1, 4, 10), (-2, 3, 0))
    camera.inset = 0.3
    w, h = offscreen.width, offscreen.height
    left = round(camera.inset * w)
    offscreen.feeder.upload(sim, eye=camera.position)
    images = {}
    for covered in (0, left):
        view = WindowView(samples=samples, scale=scale)
        try:
            offscreen.target.bind()
            GL.glClearColor(0.9, 0.2, 0.6, 1.0)  # what a stale strip would show
            GL.glClear(GL.GL_COLOR_BUFFER_BIT)
            drawn = view.begin(w, h, offscreen.target.fbo, left=covered)
            offscreen.renderer.draw(camera, *drawn, multisample=view.multisample)
            view.finish(w, h, offscreen.target.fbo)
            assert not GL.glIsEnabled(GL.GL_SCISSOR_TEST)
            images[covered] = offscreen.target.read()
        finally:
            view.delete()
            GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, 0)
    whole, cropped = images[0], images[left]
    balls = np.abs(whole[:, left:].astype(int) - whole[0, -1].astype(int)).sum(axis=-1) > 60
    assert balls.any()  # the comparison covers balls, not only the background
    assert np.array_equal(cropped[:, left:], whole[:, left:])
    assert (cropped[:, :left] == 0).all()
