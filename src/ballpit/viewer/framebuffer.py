"""An offscreen framebuffer to render into and read back: colour RGBA8 + 24-bit depth, optionally
multisampled (resolved into a single-sample buffer before reading). ``WindowView`` draws the window's
3-D view at the quality asked for (quality.py): straight into the window, multisampled and resolved
into it, or at a lower resolution and stretched over it."""

from __future__ import annotations

import numpy as np
from OpenGL import GL

from .shaders import Program


class FramebufferError(RuntimeError):
    """The driver rejected the framebuffer configuration."""


def _framebuffer(width: int, height: int, samples: int) -> tuple[int, list[int]]:
    fbo = GL.glGenFramebuffers(1)
    GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, fbo)
    color, depth = GL.glGenRenderbuffers(2)
    for rb, fmt, attachment in ((color, GL.GL_RGBA8, GL.GL_COLOR_ATTACHMENT0),
                                (depth, GL.GL_DEPTH_COMPONENT24, GL.GL_DEPTH_ATTACHMENT)):  # fmt: skip
        GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, rb)
        if samples:
            GL.glRenderbufferStorageMultisample(GL.GL_RENDERBUFFER, samples, fmt, width, height)
        else:
            GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, fmt, width, height)
        GL.glFramebufferRenderbuffer(GL.GL_FRAMEBUFFER, attachment, GL.GL_RENDERBUFFER, rb)
    status = GL.glCheckFramebufferStatus(GL.GL_FRAMEBUFFER)
    if status != GL.GL_FRAMEBUFFER_COMPLETE:
        raise FramebufferError(
            f"offscreen framebuffer {width}x{height} ({samples} samples) incomplete: {status:#x}"
        )
    return fbo, [color, depth]


class Framebuffer:
    """Bind it, draw, then ``read()`` the image as an (H, W, 3) uint8 array, top row first."""

    def __init__(self, width: int, height: int, samples: int = 0) -> None:
        self.width, self.height = int(width), int(height)
        max_samples = int(GL.glGetIntegerv(GL.GL_MAX_SAMPLES))
        self.samples = min(int(samples), max_samples) if samples else 0
        self.fbo, self._renderbuffers = _framebuffer(self.width, self.height, self.samples)
        self.resolve_fbo = None
        if self.samples:
            self.resolve_fbo, more = _framebuffer(self.width, self.height, 0)
            self._renderbuffers += more
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, 0)

    @property
    def multisample(self) -> bool:
        return self.samples > 0

    def bind(self) -> None:
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, self.fbo)

    def read(self) -> np.ndarray:
        """The rendered image, (height, width, 3) uint8, row 0 at the top."""
        source = self.fbo
        if self.resolve_fbo is not None:
            GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, self.fbo)
            GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, self.resolve_fbo)
            w, h = self.width, self.height
            GL.glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL.GL_COLOR_BUFFER_BIT, GL.GL_NEAREST)
            source = self.resolve_fbo
        GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, source)
        GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
        data = GL.glReadPixels(0, 0, self.width, self.height, GL.GL_RGB, GL.GL_UNSIGNED_BYTE)
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, self.fbo)
        image = np.frombuffer(data, dtype=np.uint8).reshape(self.height, self.width, 3)
        return image[::-1].copy()

    def delete(self) -> None:
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, 0)
        fbos = [self.fbo] + ([self.resolve_fbo] if self.resolve_fbo is not None else [])
        GL.glDeleteFramebuffers(len(fbos), fbos)
        GL.glDeleteRenderbuffers(len(self._renderbuffers), self._renderbuffers)


class WindowView:
    """Where the window's 3-D view is drawn for one ``Quality``: ``begin`` binds it and says the size to
    draw at, ``finish`` puts the image into the window's back buffer (the HUD is drawn over it after).

    At full resolution without MSAA it is the window itself. With MSAA it is a multisampled framebuffer
    resolved into the window. Smaller than the window, it is a texture that one screen-covering
    triangle stretches over the window, each texel to the pixels it covers (nearest: at half size a
    texel is a crisp 2x2 block): on llvmpipe that took 2.8 ms a frame at 1280x720 against 5.0 for
    bilinear filtering, the window's dearest step after the view itself, and glBlitFramebuffer's
    scaling path took 15-30 ms.
    """

    def __init__(self, samples: int, scale: float) -> None:
        self.samples, self.scale = int(samples), float(scale)
        self.size = (0, 0)
        self.left = 0  # window pixels at the left not drawn (begin)
        self.strip_color = (0.0, 0.0, 0.0)  # what the strip under the panel is cleared to
        self.target: Framebuffer | None = None  # drawn into (None: the window itself)
        self._texture_fbo = self._texture = self._depth = None
        self._program: Program | None = None
        self._vao = None

    @property
    def multisample(self) -> bool:
        return self.target is not None and self.target.multisample

    @property
    def keeps_image(self) -> bool:
        """Whether the last view drawn survives the frame (it is not the window's own back buffer), so
        an unchanged view can be shown again by ``finish`` alone, without drawing it."""
        return self.target is not None or self._texture is not None

    def begin(self, width: int, height: int, destination: int = 0, left: int = 0) -> tuple[int, int]:
        """Bind where to draw for a window of ``width`` x ``height`` pixels; returns the size to draw at.
        ``left``: pixels at the window's left an opaque panel covers. The view is still laid out over the
        whole window (the camera's inset centres it right of the panel), but no pixel under the panel is
        shaded or stretched: on a CPU rasteriser every pixel costs, and the panel is a quarter of a
        1280-pixel window."""
        size = (max(round(width * self.scale), 1), max(round(height * self.scale), 1))
        if size != self.size:
            self._free()
            self.size = size
            if self.samples:
                self.target = Framebuffer(*size, self.samples)
            if size != (width, height):
                self._make_texture(*size)
        self.left = min(max(int(left), 0), width)
        if self.target is not None:
            self.target.bind()
        elif self._texture_fbo is not None:
            GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, self._texture_fbo)
        else:
            GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, destination)
        if self.left:
            first = self._first_column(width)
            GL.glEnable(GL.GL_SCISSOR_TEST)
            GL.glScissor(first, 0, size[0] - first, size[1])
        return size

    def _first_column(self, width: int) -> int:
        """The view's first column drawn: the one under the panel's edge, and one more to its left
        (the texel a filtered stretch would blend into the window's first column past the panel)."""
        return max(int(self.left * self.size[0] / width) - 1, 0)

    def finish(self, width: int, height: int, destination: int = 0) -> None:
        """Resolve and stretch the view into the window's back buffer (or the framebuffer
        ``destination``) right of the panel (``begin``'s ``left``), clear the strip under the panel;
        leaves that bound, with no scissor."""
        w, h = self.size
        left = self.left
        if self.target is not None:  # resolve the samples: into the texture, or straight into the window
            GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, self.target.fbo)
            GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, self._texture_fbo or destination)
            if left:  # the columns drawn: the texture's own (as large as the view), else the window's
                first = self._first_column(width) if self._texture_fbo else left
                GL.glScissor(first, 0, w - first, h)
            GL.glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL.GL_COLOR_BUFFER_BIT, GL.GL_NEAREST)
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, destination)
        GL.glViewport(0, 0, width, height)
        if left:
            GL.glScissor(left, 0, width - left, height)
        if self._texture is not None:
            GL.glDisable(GL.GL_DEPTH_TEST)
            GL.glDisable(GL.GL_BLEND)
            self._program.use()
            GL.glActiveTexture(GL.GL_TEXTURE0)
            GL.glBindTexture(GL.GL_TEXTURE_2D, self._texture)
            GL.glBindVertexArray(self._vao)
            GL.glDrawArrays(GL.GL_TRIANGLES, 0, 3)
            GL.glBindVertexArray(0)
            GL.glBindTexture(GL.GL_TEXTURE_2D, 0)
            GL.glUseProgram(0)
        if left:  # under the panel: nothing of the view, a plain clear (the panel is drawn over it)
            GL.glScissor(0, 0, left, height)
            GL.glClearColor(*self.strip_color, 1.0)
            GL.glClear(GL.GL_COLOR_BUFFER_BIT)
            GL.glDisable(GL.GL_SCISSOR_TEST)

    def _make_texture(self, width: int, height: int) -> None:
        self._texture = GL.glGenTextures(1)
        GL.glBindTexture(GL.GL_TEXTURE_2D, self._texture)
        GL.glTexImage2D(GL.GL_TEXTURE_2D, 0, GL.GL_RGBA8, width, height, 0, GL.GL_RGBA, GL.GL_UNSIGNED_BYTE,
                        None)  # fmt: skip
        for name, value in ((GL.GL_TEXTURE_MIN_FILTER, GL.GL_NEAREST),
                            (GL.GL_TEXTURE_MAG_FILTER, GL.GL_NEAREST),
                            (GL.GL_TEXTURE_WRAP_S, GL.GL_CLAMP_TO_EDGE),
                            (GL.GL_TEXTURE_WRAP_T, GL.GL_CLAMP_TO_EDGE)):  # fmt: skip
            GL.glTexParameteri(GL.GL_TEXTURE_2D, name, value)
        GL.glBindTexture(GL.GL_TEXTURE_2D, 0)
        self._texture_fbo = GL.glGenFramebuffers(1)
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, self._texture_fbo)
        GL.glFramebufferTexture2D(
            GL.GL_FRAMEBUFFER, GL.GL_COLOR_ATTACHMENT0, GL.GL_TEXTURE_2D, self._texture, 0
        )
        if not self.samples:  # drawn into directly: it needs its own depth
            self._depth = GL.glGenRenderbuffers(1)
            GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, self._depth)
            GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, GL.GL_DEPTH_COMPONENT24, width, height)
            GL.glFramebufferRenderbuffer(GL.GL_FRAMEBUFFER, GL.GL_DEPTH_ATTACHMENT, GL.GL_RENDERBUFFER,
                                         self._depth)  # fmt: skip
        status = GL.glCheckFramebufferStatus(GL.GL_FRAMEBUFFER)
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, 0)
        if status != GL.GL_FRAMEBUFFER_COMPLETE:
            raise FramebufferError(f"view framebuffer {width}x{height} incomplete: {status:#x}")
        if self._program is None:
            self._program = Program("upscale.vert", "upscale.frag")
            self._program.use()
            self._program.set_int("u_image", 0)
            GL.glUseProgram(0)
            self._vao = GL.glGenVertexArrays(1)

    def _free(self) -> None:
        if self.target is not None:
            self.target.delete()
            self.target = None
        if self._texture_fbo is not None:
            GL.glDeleteFramebuffers(1, [self._texture_fbo])
            GL.glDeleteTextures(1, [self._texture])
            if self._depth is not None:
                GL.glDeleteRenderbuffers(1, [self._depth])
        self._texture_fbo = self._texture = self._depth = None
        self.size = (0, 0)

    def delete(self) -> None:
        """Free the GL objects (the context must be current)."""
        self._free()
        if self._program is not None:
            self._program.delete()
            GL.glDeleteVertexArrays(1, [self._vao])
            self._program = None
