"""Dear ImGui in the viewer's pyglet window: imgui-bundle's own pyglet backend, fed by the viewer.

imgui-bundle ships a pyglet 2 backend on its OpenGL 3 (core profile) renderer
(``imgui_bundle.python_backends.pyglet_backend``). Two things are changed here:

- the viewer hands it the window's events itself (``attach_callbacks=False``), so it decides what
  goes on to the 3-D view when ImGui does not want the mouse or keyboard;
- the frame's time comes from ``perf_counter``: the backend's own ``process_inputs`` calls
  ``pyglet.clock.tick()``, which would run the viewer's scheduled redraws from inside a frame.
"""

from __future__ import annotations

import ctypes
import time
from pathlib import Path

import imgui_bundle
import OpenGL.GL as gl
from imgui_bundle import imgui, implot
from imgui_bundle.python_backends.pyglet_backend import PygletProgrammablePipelineRenderer

FONT = "DroidSans.ttf"
FONT_SIZE = 15.0


class _Renderer(PygletProgrammablePipelineRenderer):
    """The backend's renderer, saving and restoring only the GL state the viewer's frame relies on.

    The backend's own ``render`` saves and restores some twenty values with ``glGet`` through PyOpenGL
    before and after every frame; on llvmpipe one of them (the alpha blend equation) costs 0.17 ms
    alone. The viewer draws nothing after the panel in a frame, and its next frame sets the state each
    of its passes needs, except what is restored here."""

    def render(self, draw_data: imgui.ImDrawData, fresh: bool = True) -> None:
        """Draw ImGui's triangles. Every draw list goes into the same two buffers, one after another, so
        not ``fresh`` (the same draw data as last time, drawn again) the buffers still hold them all and
        nothing is uploaded. A command binds its texture and sets its clip rectangle only when they
        differ from the command before it."""
        io = self.io
        width, height = io.display_size
        fb_width = int(width * io.display_framebuffer_scale[0])
        fb_height = int(height * io.display_framebuffer_scale[1])
        self._update_textures()
        if fb_width == 0 or fb_height == 0:
            return
        if fresh:
            draw_data.scale_clip_rects(io.display_framebuffer_scale)
        enabled = {cap: gl.glIsEnabled(cap) for cap in (gl.GL_BLEND, gl.GL_CULL_FACE, gl.GL_DEPTH_TEST)}
        viewport = gl.glGetIntegerv(gl.GL_VIEWPORT)
        gl.glEnable(gl.GL_BLEND)
        gl.glBlendEquation(gl.GL_FUNC_ADD)
        gl.glBlendFunc(gl.GL_SRC_ALPHA, gl.GL_ONE_MINUS_SRC_ALPHA)
        gl.glDisable(gl.GL_CULL_FACE)
        gl.glDisable(gl.GL_DEPTH_TEST)
        gl.glEnable(gl.GL_SCISSOR_TEST)
        gl.glActiveTexture(gl.GL_TEXTURE0)
        gl.glViewport(0, 0, fb_width, fb_height)
        projection = (ctypes.c_float * 16)(
            2.0 / width, 0.0, 0.0, 0.0, 0.0, -2.0 / height, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, -1.0, 1.0, 0.0, 1.0
        )
        gl.glUseProgram(self._shader_handle)
        gl.glUniform1i(self._attrib_location_tex, 0)
        gl.glUniformMatrix4fv(self._attrib_proj_mtx, 1, gl.GL_FALSE, projection)
        gl.glBindVertexArray(self._vao_handle)
        lists = draw_data.cmd_lists
        if fresh or self._bases is None:
            self._bases = self._upload(lists)
        for commands, (base_vertex, base_index) in zip(lists, self._bases, strict=True):
            self._draw_list(commands, fb_height, base_vertex, base_index)
        gl.glDisable(gl.GL_SCISSOR_TEST)
        for cap, on in enabled.items():
            (gl.glEnable if on else gl.glDisable)(cap)
        gl.glViewport(*viewport)
        gl.glBindVertexArray(0)
        gl.glUseProgram(0)
        self._handle_mouse_cursor()

    def _upload(self, lists: list[imgui.ImDrawList]) -> list[tuple[int, int]]:
        """Every draw list's vertices and indices into the two buffers, one after another; returns where
        each list starts (its first vertex, its first index)."""
        vertices = sum(commands.vtx_buffer.size() for commands in lists)
        indices = sum(commands.idx_buffer.size() for commands in lists)
        gl.glBindBuffer(gl.GL_ARRAY_BUFFER, self._vbo_handle)
        gl.glBufferData(gl.GL_ARRAY_BUFFER, vertices * imgui.VERTEX_SIZE, None, gl.GL_STREAM_DRAW)
        gl.glBindBuffer(gl.GL_ELEMENT_ARRAY_BUFFER, self._elements_handle)
        gl.glBufferData(gl.GL_ELEMENT_ARRAY_BUFFER, indices * imgui.INDEX_SIZE, None, gl.GL_STREAM_DRAW)
        bases, vertex, index = [], 0, 0
        for commands in lists:
            bases.append((vertex, index))
            for target, data, size, at in (
                (gl.GL_ARRAY_BUFFER, commands.vtx_buffer, imgui.VERTEX_SIZE, vertex),
                (gl.GL_ELEMENT_ARRAY_BUFFER, commands.idx_buffer, imgui.INDEX_SIZE, index),
            ):
                gl.glBufferSubData(
                    target, at * size, data.size() * size, ctypes.c_void_p(data.data_address())
                )
            vertex += commands.vtx_buffer.size()
            index += commands.idx_buffer.size()
        self.uploads += 1
        return bases

    def _draw_list(
        self, commands: imgui.ImDrawList, fb_height: int, base_vertex: int, base_index: int
    ) -> None:
        """The commands of one of ImGui's draw lists, whose vertices and indices start at ``base_vertex``
        and ``base_index`` in the buffers."""
        index_type = gl.GL_UNSIGNED_SHORT if imgui.INDEX_SIZE == 2 else gl.GL_UNSIGNED_INT
        texture, clip = None, None
        for command in commands.cmd_buffer:
            tex = command.tex_ref.get_tex_id()
            if tex != texture:
                gl.glBindTexture(gl.GL_TEXTURE_2D, tex)
                texture = tex
            x, y, z, w = command.clip_rect
            rect = (int(x), int(fb_height - w), int(z - x), int(w - y))
            if rect != clip:
                gl.glScissor(*rect)
                clip = rect
            gl.glDrawElementsBaseVertex(
                gl.GL_TRIANGLES,
                command.elem_count,
                index_type,
                ctypes.c_void_p((base_index + command.idx_offset) * imgui.INDEX_SIZE),
                base_vertex + command.vtx_offset,
            )


class PanelBackend:
    """One ImGui (and ImPlot) context drawn into ``window``; ``new_frame`` … ``render`` per frame."""

    def __init__(self, window: object) -> None:
        self.window = window
        self.context = imgui.create_context()
        self.plot_context = implot.create_context()
        io = imgui.get_io()
        io.set_ini_filename("")  # no imgui.ini in the user's folder: the layout is the viewer's
        io.config_flags |= imgui.ConfigFlags_.no_mouse_cursor_change
        font = Path(imgui_bundle.__file__).parent / "assets" / "fonts" / FONT
        if font.is_file():  # the wheel's Droid Sans: ×, °, … and ² that ImGui's own font lacks
            io.font_default = io.fonts.add_font_from_file_ttf(str(font), FONT_SIZE)
        self.renderer = _Renderer(window, attach_callbacks=False)
        self.renderer._window = window
        self.renderer._bases = None  # where each draw list drawn last starts in the GL buffers
        self.renderer.uploads = 0  # frames whose draw lists were uploaded to the GL buffers
        self._last = time.perf_counter()
        self._pointer: tuple[float, float] | None = None
        self.fed = True  # input came since the last build: the next frame builds the panel again
        self._built = False
        self.builds = self.redraws = 0  # frames that built the panel, and that drew the last build again

    def activate(self) -> None:
        """Make this panel's ImGui and ImPlot contexts current (each window has its own)."""
        imgui.set_current_context(self.context)
        implot.set_current_context(self.plot_context)

    # ------------------------------------------------------------------ events (window coordinates, y up)
    def mouse_motion(self, x: float, y: float) -> None:
        self.fed = True
        self.activate()
        self.renderer.on_mouse_motion(x, y, 0, 0)
        self._pointer = (x, y)

    def mouse_button(self, x: float, y: float, button: int, down: bool) -> None:
        self.fed = True
        self.activate()
        self.mouse_motion(x, y)
        self.renderer._on_mouse_button(button, down)

    def scroll(self, x: float, y: float, scroll_x: float, scroll_y: float) -> None:
        self.fed = True
        self.activate()
        self.mouse_motion(x, y)
        self.renderer.on_mouse_scroll(x, y, scroll_x, scroll_y)

    def key(self, symbol: int, down: bool) -> None:
        self.fed = True
        self.activate()
        self.renderer._on_key(symbol, down)

    def text(self, text: str) -> None:
        self.fed = True
        self.activate()
        self.renderer.on_text(text)

    def resize(self) -> None:
        self.fed = True
        self.activate()
        self.renderer.on_resize(0, 0)

    # ------------------------------------------------------------------ what ImGui wants
    @property
    def wants_keyboard(self) -> bool:
        """A text field or a slider being typed into has the keyboard: keys do not reach the viewer."""
        self.activate()
        io = imgui.get_io()
        return bool(io.want_capture_keyboard or io.want_text_input)

    @property
    def wants_mouse(self) -> bool:
        self.activate()
        return bool(imgui.get_io().want_capture_mouse)

    # ------------------------------------------------------------------ the frame
    def new_frame(self) -> None:
        self.activate()
        now = time.perf_counter()
        io = imgui.get_io()
        io.delta_time = min(max(now - self._last, 1e-4), 0.25)
        self._last = now
        self.renderer._set_pixel_ratio(self.window)
        imgui.new_frame()
        self.fed = False
        self.builds += 1

    def render(self) -> None:
        imgui.render()
        self._built = True
        self.renderer.render(imgui.get_draw_data())

    def can_redraw(self) -> bool:
        """Whether ``redraw`` would draw: a frame was built and no input came since."""
        return self._built and not self.fed

    def redraw(self) -> bool:
        """Draw the last built frame again (ImGui keeps its draw data until the next ``new_frame``);
        False, drawing nothing, when input came since or there is no frame to draw. Its clip rectangles
        were scaled to the framebuffer when it was built, and are not scaled again."""
        self.activate()
        if not self.can_redraw():
            return False
        self.renderer.render(imgui.get_draw_data(), fresh=False)
        self.redraws += 1
        return True

    def shutdown(self) -> None:
        """Free the GL objects (with the window's context current) and the contexts."""
        if self.context is None:
            return
        self.activate()
        self.renderer.shutdown()
        implot.destroy_context(self.plot_context)
        imgui.destroy_context(self.context)
        self.context = None
