"""OpenGL 3.3 core renderer: planes, instanced balls and debug lines, drawn with PyOpenGL.

Import this only after ``backend.use_window()`` or ``backend.use_headless()`` and with a GL context
current. Per frame the CPU work is whole-array NumPy plus a handful of GL calls: the balls are one
instance-buffer upload and one ``glDrawArraysInstanced`` whatever their number. Every draw goes through
``DrawLog`` so tests and benchmarks can see exactly which draw calls a frame made.

Planes are drawn in up to three passes. Their front faces (the side the normal points to, where a
scene puts its balls) are opaque and drawn first. A solid plane (``solid_planes``: a finite floor or
slope, one facing up when the scene starts) is opaque from behind too, in its own colour and lit as a
face of its own, so a slope tilted over keeps its colour; those back faces are a second opaque pass.
The back faces of the other planes are the walls you look through, such as the near wall of a closed
box seen from outside, so they are drawn see-through after the balls (blended, not writing depth).
The back passes are skipped when the eye is on the front side of every plane they would draw.

The balls cast shadows onto the planes' opaque faces and darken them where they touch (see
shadows.py): each frame the balls are binned in a grid seen from the sun, uploaded as two texture
buffers that the plane shader reads. That is NumPy work on the CPU and no extra draw call. The solid
planes cast shadows on the other planes and on the balls (at most ``MAX_CASTERS``, passed as uniforms:
casters.glsl), so a ball's shadow ends at the first plane under it.
"""

from __future__ import annotations

import ctypes
import time
from dataclasses import dataclass, field

import numpy as np
from OpenGL import GL

from . import shadows
from .camera import Camera
from .overlays import VERTEX_WIDTH
from .shaders import Program

BACKGROUND = (0.105, 0.125, 0.165)  # sRGB clear colour; fog fades to it
FOG_DENSITY = 0.02  # 1/m: fog is light at 20 m, the ground faint by 60 m and gone by 100 m
GROUND_EXTENT = 600.0  # half size (m) of the quad drawn for an infinite plane
NO_EDGE = 1.0e6  # "half size" given to the shader for infinite planes: no edge band
BALL_STRIDE = 12  # floats per instance: centre (3), radius, quaternion (4), colour (3), spare
PLANE_STRIDE = 14  # floats per plane vertex: position (3), local (2), half size (2), normal (3), colour (3),
# solid (1)
MAX_CASTERS = 16  # solid planes that cast shadows at most (plane.frag's MAX_CASTERS); the first ones
SOLID_FACING = 0.5  # a finite plane whose normal's y is above this at the start is a floor or slope
SORT_THRESHOLD = 256  # sort balls front to back above this many
SHADOW_BALLS_UNIT, SHADOW_CELLS_UNIT = 1, 2  # texture units of the shadow grid's buffers
_FLOAT = 4


@dataclass
class DrawCall:
    label: str
    function: str
    count: int
    instances: int = 1


@dataclass
class DrawLog:
    """Forwards draw calls to GL and records them for the current frame."""

    calls: list[DrawCall] = field(default_factory=list)

    def reset(self) -> None:
        self.calls.clear()

    def arrays(self, label: str, mode: int, first: int, count: int) -> None:
        self.calls.append(DrawCall(label, "glDrawArrays", count))
        GL.glDrawArrays(mode, first, count)

    def arrays_instanced(self, label: str, mode: int, first: int, count: int, instances: int) -> None:
        self.calls.append(DrawCall(label, "glDrawArraysInstanced", count, instances))
        GL.glDrawArraysInstanced(mode, first, count, instances)

    def count(self, label: str) -> int:
        return sum(1 for c in self.calls if c.label == label)


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors ``v`` (..., 3) by unit quaternions ``q`` (..., 4), scalar last."""
    u, w = q[..., :3], q[..., 3:4]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def solid_planes(orientations: np.ndarray, half_sizes: np.ndarray) -> np.ndarray:
    """Which planes are solid: finite and facing up (a floor or a slope, normal's y above
    ``SOLID_FACING``). The others (walls, ceilings, the infinite ground) are seen through from behind,
    so a closed box shows what is inside it, and they cast no shadow."""
    q = np.asarray(orientations, dtype=float).reshape(-1, 4)
    finite = np.isfinite(np.asarray(half_sizes, dtype=float).reshape(-1, 2)).all(axis=1)
    up = rotate(q, np.broadcast_to([0.0, 1.0, 0.0], (len(q), 3)))[:, 1]
    return finite & (up > SOLID_FACING)


def _offset(floats: int) -> ctypes.c_void_p:
    return ctypes.c_void_p(floats * _FLOAT)


def _vertex_array() -> tuple[int, int]:
    """A vertex array and its buffer of (x, y, z, r, g, b, a) vertices, left bound."""
    vao, vbo = GL.glGenVertexArrays(1), GL.glGenBuffers(1)
    GL.glBindVertexArray(vao)
    GL.glBindBuffer(GL.GL_ARRAY_BUFFER, vbo)
    _attribute(0, 3, VERTEX_WIDTH, 0)
    _attribute(1, 4, VERTEX_WIDTH, 3)
    return vao, vbo


def _attribute(index: int, size: int, stride_floats: int, offset_floats: int, divisor: int = 0) -> None:
    GL.glEnableVertexAttribArray(index)
    GL.glVertexAttribPointer(
        index, size, GL.GL_FLOAT, GL.GL_FALSE, stride_floats * _FLOAT, _offset(offset_floats)
    )
    if divisor:
        GL.glVertexAttribDivisor(index, divisor)


class Renderer:
    """Owns the GL programs and buffers of the 3-D view (not the HUD)."""

    def __init__(self, shader_directory: object = None) -> None:
        self._shader_directory = shader_directory
        # the ball and plane programs by the number of shadow casters they were compiled for
        self._caster_programs: dict[int, tuple[Program, Program]] = {}
        self._programs_for(0)
        self.line_program = Program("line.vert", "line.frag", shader_directory)
        self.draws = DrawLog()
        self.background = np.array(BACKGROUND, dtype=np.float32)
        self.fog_density = FOG_DENSITY
        self.upload_seconds = 0.0
        self.draw_seconds = 0.0

        # balls: a static quad (4 corners, triangle strip) and the per-instance buffer
        self.ball_vao = GL.glGenVertexArrays(1)
        self.corner_vbo, self.instance_vbo = GL.glGenBuffers(2)
        GL.glBindVertexArray(self.ball_vao)
        corners = np.array([[-1, -1], [1, -1], [-1, 1], [1, 1]], dtype=np.float32)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.corner_vbo)
        GL.glBufferData(GL.GL_ARRAY_BUFFER, corners.nbytes, corners, GL.GL_STATIC_DRAW)
        _attribute(0, 2, 2, 0)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.instance_vbo)
        _attribute(1, 4, BALL_STRIDE, 0, divisor=1)  # centre, radius
        _attribute(2, 4, BALL_STRIDE, 4, divisor=1)  # orientation
        _attribute(3, 4, BALL_STRIDE, 8, divisor=1)  # colour
        self._instances = np.zeros((0, BALL_STRIDE), dtype=np.float32)
        self._sorted = np.zeros((0, BALL_STRIDE), dtype=np.float32)
        self.ball_count = 0

        # ghost balls (G): the same quad, their own instance buffer, drawn translucent after the balls
        self.ghost_vao = GL.glGenVertexArrays(1)
        self.ghost_vbo = GL.glGenBuffers(1)
        GL.glBindVertexArray(self.ghost_vao)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.corner_vbo)
        _attribute(0, 2, 2, 0)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.ghost_vbo)
        _attribute(1, 4, BALL_STRIDE, 0, divisor=1)
        _attribute(2, 4, BALL_STRIDE, 4, divisor=1)
        _attribute(3, 4, BALL_STRIDE, 8, divisor=1)
        self.ghost_count = 0
        self.ghost_alpha = 0.4
        self._ghost_instances = np.zeros((0, BALL_STRIDE), dtype=np.float32)

        # planes: two triangles each, rebuilt when the scene changes or a plane moves
        self.plane_vao = GL.glGenVertexArrays(1)
        self.plane_vbo = GL.glGenBuffers(1)
        GL.glBindVertexArray(self.plane_vao)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.plane_vbo)
        for index, (size, offset) in enumerate([(3, 0), (2, 3), (2, 5), (3, 7), (3, 10), (1, 13)]):
            _attribute(index, size, PLANE_STRIDE, offset)
        self.plane_vertices = 0
        self.selected_plane = -1  # drawn with a highlighted rim (or tint, if infinite); -1: none
        self._plane_centers = np.zeros((0, 3))
        self._plane_normals = np.zeros((0, 3))
        self._plane_solid = np.zeros(0, dtype=bool)
        self._casters: dict[str, np.ndarray] = {}
        self._caster_index = np.zeros(0, dtype=int)

        # ball shadows: the grid of balls seen from the sun, two texture buffers the plane shader reads
        self.shadows = True  # False: planes are drawn without ball shadows or contact darkening
        self.sun_direction = np.asarray(shadows.SUN_DIRECTION, dtype=np.float32)
        self.shadow_limit = shadows.LIMIT  # balls kept per grid cell
        self.shadow_grid = shadows.empty_grid(self.sun_direction)
        self.shadow_seconds = 0.0
        self.shadow_buffers = GL.glGenBuffers(2)
        self.shadow_textures = GL.glGenTextures(2)
        for buffer, texture, fmt in zip(
            self.shadow_buffers, self.shadow_textures, (GL.GL_RGBA32F, GL.GL_RG32I), strict=True
        ):
            GL.glBindBuffer(GL.GL_TEXTURE_BUFFER, buffer)
            GL.glBufferData(GL.GL_TEXTURE_BUFFER, 16, None, GL.GL_STREAM_DRAW)
            GL.glBindTexture(GL.GL_TEXTURE_BUFFER, texture)
            GL.glTexBuffer(GL.GL_TEXTURE_BUFFER, fmt, buffer)
        GL.glBindTexture(GL.GL_TEXTURE_BUFFER, 0)
        GL.glBindBuffer(GL.GL_TEXTURE_BUFFER, 0)

        # trails (a triangle strip, depth tested) then overlay lines (always on top), in one buffer
        self.line_vao, self.line_vbo = _vertex_array()
        self.trail_vertices = 0
        self.overlay_line_vertices = 0

        # screen-space overlays in window pixels (timeline bar, energy plot): triangles, then lines
        self.screen_vao, self.screen_vbo = _vertex_array()
        self.screen_triangle_vertices = 0
        self.screen_line_vertices = 0
        self.screen_size = (1.0, 1.0)

        GL.glBindVertexArray(0)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, 0)

    # ------------------------------------------------------------------ uploads
    def set_planes(
        self, centers: np.ndarray, orientations: np.ndarray, half_sizes: np.ndarray, colors: np.ndarray,
        solid: np.ndarray | None = None,
    ) -> None:  # fmt: skip
        """Build the plane quads: when the scene changes or a plane moved (a few planes: cheap).
        ``solid``: which planes are opaque from behind and cast shadows (default: ``solid_planes`` of
        these poses; the window passes the scene's start, so a slope tilted over stays solid)."""
        centers = np.asarray(centers, dtype=float).reshape(-1, 3)
        count = len(centers)
        q = np.asarray(orientations, dtype=float).reshape(-1, 4)
        half = np.asarray(half_sizes, dtype=float).reshape(-1, 2)
        infinite = ~np.isfinite(half)
        drawn_half = np.where(infinite, GROUND_EXTENT, half)
        shader_half = np.where(infinite, NO_EDGE, half)
        u = rotate(q, np.broadcast_to([1.0, 0.0, 0.0], (count, 3)))
        n = rotate(q, np.broadcast_to([0.0, 1.0, 0.0], (count, 3)))
        v = rotate(q, np.broadcast_to([0.0, 0.0, 1.0], (count, 3)))
        solid = solid_planes(q, half) if solid is None else np.asarray(solid, dtype=bool).reshape(count)
        # corners in plane-local units, two counter-clockwise triangles seen from the normal's side
        local = np.array([[-1, -1], [-1, 1], [1, 1], [-1, -1], [1, 1], [1, -1]], dtype=float)
        local = local[None] * drawn_half[:, None, :]  # (P, 6, 2)
        positions = centers[:, None, :] + local[..., :1] * u[:, None, :] + local[..., 1:] * v[:, None, :]
        data = np.empty((count, 6, PLANE_STRIDE), dtype=np.float32)
        data[..., 0:3] = positions
        data[..., 3:5] = local
        data[..., 5:7] = shader_half[:, None, :]
        data[..., 7:10] = n[:, None, :]
        data[..., 10:13] = np.asarray(colors, dtype=float).reshape(-1, 3)[:, None, :]
        data[..., 13] = solid[:, None]
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.plane_vbo)
        GL.glBufferData(GL.GL_ARRAY_BUFFER, data.nbytes, data, GL.GL_DYNAMIC_DRAW)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, 0)
        self.plane_vertices = count * 6
        self._plane_centers, self._plane_normals, self._plane_solid = centers, n, solid
        casts = np.flatnonzero(solid & ~infinite.any(axis=1))[:MAX_CASTERS]
        self._casters = {"u_caster_center": centers[casts], "u_caster_u": u[casts], "u_caster_v": v[casts],
                         "u_caster_half": half[casts], "u_caster_normal": n[casts]}  # fmt: skip
        self._caster_index = casts
        self._programs_for(len(casts))

    def _programs_for(self, casters: int) -> None:
        """Draw balls and planes with the programs compiled for ``casters`` shadow casters (compiled
        the first time that count is asked for: the casters are written out one by one in the shader,
        casters.glsl, so a frame pays for the casters the scene has, not for ``MAX_CASTERS``)."""
        programs = self._caster_programs.get(casters)
        if programs is None:
            defines = {"CASTERS": casters}
            directory = self._shader_directory
            ball = Program("ball.vert", "ball.frag", directory, defines)
            plane = Program("plane.vert", "plane.frag", directory, defines)
            plane.use()
            plane.set_int("u_shadow_balls", SHADOW_BALLS_UNIT)
            plane.set_int("u_shadow_cells", SHADOW_CELLS_UNIT)
            GL.glUseProgram(0)
            programs = self._caster_programs[casters] = (ball, plane)
        self.ball_program, self.plane_program = programs

    def upload_balls(
        self,
        positions: np.ndarray,
        orientations: np.ndarray,
        radii: np.ndarray,
        colors: np.ndarray,
        eye: np.ndarray | None = None,
    ) -> None:
        """Fill the per-instance buffer from whole arrays: one ``glBufferData`` for all balls.

        Given the ``eye``, many balls are ordered nearest first, so the depth test rejects the hidden
        ones before they are shaded (it halves the draw of a 10,000-ball pile on a CPU rasteriser).
        The shadow grid is rebuilt from the same positions.
        """
        started = time.perf_counter()
        self.upload_shadows(positions, radii)
        n = len(positions)
        if self._instances.shape[0] != n:
            self._instances = np.zeros((n, BALL_STRIDE), dtype=np.float32)
            self._instances[:, 11] = 1.0
            self._sorted = np.zeros_like(self._instances)
        inst = self._instances
        inst[:, 0:3] = positions
        inst[:, 3] = radii
        inst[:, 4:8] = orientations
        inst[:, 8:11] = colors
        if eye is not None and n > SORT_THRESHOLD:  # in float32, then one gather of whole rows
            offset = inst[:, 0:3] - np.asarray(eye, dtype=np.float32)
            order = np.argsort(np.einsum("ij,ij->i", offset, offset))
            inst = np.take(inst, order, axis=0, out=self._sorted)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.instance_vbo)
        GL.glBufferData(GL.GL_ARRAY_BUFFER, inst.nbytes, inst if n else None, GL.GL_STREAM_DRAW)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, 0)
        self.ball_count = n
        self.upload_seconds = time.perf_counter() - started

    def upload_shadows(self, positions: np.ndarray, radii: np.ndarray) -> None:
        """Bin the balls in the sun's grid and upload it (two buffer uploads, whatever the count)."""
        started = time.perf_counter()
        if self.shadows and len(positions):
            grid = shadows.build(positions, radii, self.sun_direction, limit=self.shadow_limit)
        else:
            grid = shadows.empty_grid(self.sun_direction)
        for buffer, data in zip(self.shadow_buffers, (grid.balls, grid.ranges), strict=True):
            GL.glBindBuffer(GL.GL_TEXTURE_BUFFER, buffer)
            GL.glBufferData(GL.GL_TEXTURE_BUFFER, max(data.nbytes, 16), data if data.nbytes else None,
                            GL.GL_STREAM_DRAW)  # fmt: skip
        GL.glBindBuffer(GL.GL_TEXTURE_BUFFER, 0)
        self.shadow_grid = grid
        self.shadow_seconds = time.perf_counter() - started

    def upload_ghosts(
        self, positions: np.ndarray, orientations: np.ndarray, radii: np.ndarray, colors: np.ndarray,
        alpha: float = 0.4,
    ) -> None:  # fmt: skip
        """The ghost balls of every ghost world at once (one instanced draw), drawn with ``alpha``."""
        n = len(positions)
        if self._ghost_instances.shape[0] != n:
            self._ghost_instances = np.zeros((n, BALL_STRIDE), dtype=np.float32)
            self._ghost_instances[:, 11] = 1.0
        inst = self._ghost_instances
        inst[:, 0:3] = positions
        inst[:, 3] = radii
        inst[:, 4:8] = orientations
        inst[:, 8:11] = colors
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.ghost_vbo)
        GL.glBufferData(GL.GL_ARRAY_BUFFER, inst.nbytes, inst if n else None, GL.GL_STREAM_DRAW)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, 0)
        self.ghost_count = n
        self.ghost_alpha = float(alpha)

    def upload_screen(self, triangles: np.ndarray, lines: np.ndarray, size: tuple[float, float]) -> None:
        """Screen-space vertices (M, 7) in pixels of a window ``size`` (y up): panels, then lines."""
        data = np.concatenate([triangles, lines]).astype(np.float32, copy=False)
        self.screen_triangle_vertices, self.screen_line_vertices = len(triangles), len(lines)
        self.screen_size = (max(float(size[0]), 1.0), max(float(size[1]), 1.0))
        if len(data):
            GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.screen_vbo)
            GL.glBufferData(GL.GL_ARRAY_BUFFER, data.nbytes, data, GL.GL_STREAM_DRAW)
            GL.glBindBuffer(GL.GL_ARRAY_BUFFER, 0)

    def upload_lines(self, trails: np.ndarray, overlay_lines: np.ndarray) -> None:
        """Vertices (M, 7) for this frame: the trails' triangle strip (depth-tested; overlays.py), then
        the always-visible overlay lines."""
        data = np.concatenate([trails, overlay_lines]).astype(np.float32, copy=False)
        self.trail_vertices = len(trails)
        self.overlay_line_vertices = len(overlay_lines)
        if len(data):
            GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.line_vbo)
            GL.glBufferData(GL.GL_ARRAY_BUFFER, data.nbytes, data, GL.GL_STREAM_DRAW)
            GL.glBindBuffer(GL.GL_ARRAY_BUFFER, 0)

    # ------------------------------------------------------------------ drawing
    def _common_uniforms(self, program: Program, view_projection: np.ndarray, eye: np.ndarray) -> None:
        program.use()
        program.set("u_view_projection", view_projection)
        program.set("u_eye", eye)
        program.set("u_background", self.background)
        program.set("u_fog_density", self.fog_density)
        program.set("u_sun_direction", self.sun_direction)
        if program is self.plane_program:
            program.set("u_selected", int(self.selected_plane))

    def _shadow_uniforms(self, program: Program) -> None:
        """The sun's grid for the plane shader, with its buffers bound to their texture units."""
        grid = self.shadow_grid
        program.set("u_shadow_axis_u", grid.axes[0])
        program.set("u_shadow_axis_v", grid.axes[1])
        program.set("u_shadow_origin", grid.origin)
        program.set("u_shadow_inverse_cell", 1.0 / grid.cell_size)
        program.set("u_shadow_shape", np.array(grid.shape, dtype=np.float32))
        program.set("u_shadow_reach", shadows.REACH)
        self._caster_uniforms(program)

    def _caster_uniforms(self, program: Program) -> None:
        """The solid planes that cast shadows (casters.glsl), for the plane or the ball shader."""
        casts = self._caster_index if self.shadows else np.zeros(0, dtype=int)
        program.set_int("u_caster_count", len(casts))
        if len(casts):
            for name, values in self._casters.items():
                program.set_array(name, values)
            program.set_int_array("u_caster_index", casts)
        for unit, texture in ((SHADOW_BALLS_UNIT, self.shadow_textures[0]),
                              (SHADOW_CELLS_UNIT, self.shadow_textures[1])):  # fmt: skip
            GL.glActiveTexture(GL.GL_TEXTURE0 + unit)
            GL.glBindTexture(GL.GL_TEXTURE_BUFFER, texture)
        GL.glActiveTexture(GL.GL_TEXTURE0)

    def seen_from_behind(self, eye: np.ndarray) -> np.ndarray:
        """Which planes have the eye on their back side, as a bool array."""
        return np.einsum("ij,ij->i", eye[None, :] - self._plane_centers, self._plane_normals) < 0.0

    def _back_faces(self, label: str, solid: bool, view_projection: np.ndarray, eye: np.ndarray) -> None:
        """The planes' back faces: the solid ones opaque, else the see-through ones blended."""
        self._common_uniforms(self.plane_program, view_projection, eye)
        self.plane_program.set("u_back_pass", 1.0 if solid else 0.0)
        if solid:
            self._shadow_uniforms(self.plane_program)
        GL.glEnable(GL.GL_CULL_FACE)
        GL.glCullFace(GL.GL_FRONT)
        if not solid:
            GL.glEnable(GL.GL_BLEND)
            GL.glBlendFunc(GL.GL_SRC_ALPHA, GL.GL_ONE_MINUS_SRC_ALPHA)
            GL.glDepthMask(GL.GL_FALSE)
        GL.glBindVertexArray(self.plane_vao)
        self.draws.arrays(label, GL.GL_TRIANGLES, 0, self.plane_vertices)
        GL.glDepthMask(GL.GL_TRUE)
        GL.glDisable(GL.GL_BLEND)
        GL.glDisable(GL.GL_CULL_FACE)

    def draw(self, camera: Camera, width: int, height: int, multisample: bool = False) -> None:
        """Clear and draw the scene into the bound framebuffer's (0, 0, width, height) viewport."""
        started = time.perf_counter()
        self.draws.reset()
        width, height = max(int(width), 1), max(int(height), 1)
        view_projection = camera.view_projection(width / height)
        eye = np.asarray(camera.position, dtype=np.float32)

        GL.glViewport(0, 0, width, height)
        GL.glClearColor(*self.background, 1.0)
        GL.glClear(GL.GL_COLOR_BUFFER_BIT | GL.GL_DEPTH_BUFFER_BIT)
        GL.glEnable(GL.GL_DEPTH_TEST)
        GL.glDepthFunc(GL.GL_LEQUAL)
        GL.glDepthMask(GL.GL_TRUE)
        GL.glDisable(GL.GL_BLEND)

        if self.plane_vertices:  # front faces, opaque, with the balls' shadows
            self._common_uniforms(self.plane_program, view_projection, eye)
            self._shadow_uniforms(self.plane_program)
            GL.glEnable(GL.GL_CULL_FACE)
            GL.glCullFace(GL.GL_BACK)
            GL.glBindVertexArray(self.plane_vao)
            self.draws.arrays("planes", GL.GL_TRIANGLES, 0, self.plane_vertices)
            GL.glDisable(GL.GL_CULL_FACE)  # ball quads face the camera anyway
        behind = self.seen_from_behind(camera.position) if self.plane_vertices else np.zeros(0, dtype=bool)
        if (behind & self._plane_solid).any():
            self._back_faces("solid plane backs", True, view_projection, eye)

        if self.ball_count:
            self._common_uniforms(self.ball_program, view_projection, eye)
            self._caster_uniforms(self.ball_program)
            self.ball_program.set("u_multisample", 1.0 if multisample else 0.0)
            self.ball_program.set("u_alpha", 1.0)
            if multisample:
                GL.glEnable(GL.GL_SAMPLE_ALPHA_TO_COVERAGE)
            GL.glBindVertexArray(self.ball_vao)
            self.draws.arrays_instanced("balls", GL.GL_TRIANGLE_STRIP, 0, 4, self.ball_count)
            if multisample:
                GL.glDisable(GL.GL_SAMPLE_ALPHA_TO_COVERAGE)

        if self.ghost_count:  # translucent ghosts: blended, not writing depth
            self._common_uniforms(self.ball_program, view_projection, eye)
            self._caster_uniforms(self.ball_program)
            self.ball_program.set("u_multisample", 1.0 if multisample else 0.0)
            self.ball_program.set("u_alpha", self.ghost_alpha)
            GL.glEnable(GL.GL_BLEND)
            GL.glBlendFunc(GL.GL_SRC_ALPHA, GL.GL_ONE_MINUS_SRC_ALPHA)
            GL.glDepthMask(GL.GL_FALSE)
            GL.glBindVertexArray(self.ghost_vao)
            self.draws.arrays_instanced("ghosts", GL.GL_TRIANGLE_STRIP, 0, 4, self.ghost_count)
            GL.glDepthMask(GL.GL_TRUE)
            GL.glDisable(GL.GL_BLEND)

        if (behind & ~self._plane_solid).any():  # back faces, see-through
            self._back_faces("see-through planes", False, view_projection, eye)

        if self.trail_vertices or self.overlay_line_vertices:
            self.line_program.use()
            self.line_program.set("u_view_projection", view_projection)
            GL.glEnable(GL.GL_BLEND)
            GL.glBlendFunc(GL.GL_SRC_ALPHA, GL.GL_ONE_MINUS_SRC_ALPHA)
            GL.glDepthMask(GL.GL_FALSE)
            GL.glBindVertexArray(self.line_vao)
            if self.trail_vertices:
                self.draws.arrays("trails", GL.GL_TRIANGLE_STRIP, 0, self.trail_vertices)
            if self.overlay_line_vertices:
                GL.glDisable(GL.GL_DEPTH_TEST)
                self.draws.arrays(
                    "overlay lines", GL.GL_LINES, self.trail_vertices, self.overlay_line_vertices
                )
            GL.glDepthMask(GL.GL_TRUE)

        if self.screen_triangle_vertices or self.screen_line_vertices:
            w, h = self.screen_size
            # row-vector layout, like the camera's: [x, y, z, 1] @ M maps pixels to clip space
            pixels_to_clip = np.array([[2 / w, 0, 0, 0], [0, 2 / h, 0, 0], [0, 0, 1, 0], [-1, -1, 0, 1]],
                                      dtype=np.float32)  # fmt: skip
            self.line_program.use()
            self.line_program.set("u_view_projection", pixels_to_clip)
            GL.glDisable(GL.GL_DEPTH_TEST)
            GL.glEnable(GL.GL_BLEND)
            GL.glBlendFunc(GL.GL_SRC_ALPHA, GL.GL_ONE_MINUS_SRC_ALPHA)
            GL.glBindVertexArray(self.screen_vao)
            if self.screen_triangle_vertices:
                self.draws.arrays("screen panels", GL.GL_TRIANGLES, 0, self.screen_triangle_vertices)
            if self.screen_line_vertices:
                self.draws.arrays(
                    "screen lines", GL.GL_LINES, self.screen_triangle_vertices, self.screen_line_vertices
                )

        # leave the state pyglet's own drawing (the HUD) expects
        GL.glBindVertexArray(0)
        GL.glUseProgram(0)
        GL.glDisable(GL.GL_DEPTH_TEST)
        GL.glDisable(GL.GL_BLEND)
        # hand the view to the rasteriser now: a CPU one (llvmpipe) draws it on its own thread while the
        # caller lays out what goes over it, instead of starting when the image is first read
        GL.glFlush()
        self.draw_seconds = time.perf_counter() - started

    def delete(self) -> None:
        """Free the GL objects (the context must be current)."""
        for program in (*(p for pair in self._caster_programs.values() for p in pair), self.line_program):
            program.delete()
        self._caster_programs.clear()
        GL.glDeleteBuffers(
            6,
            [
                self.corner_vbo,
                self.instance_vbo,
                self.plane_vbo,
                self.line_vbo,
                self.ghost_vbo,
                self.screen_vbo,
            ],
        )
        GL.glDeleteVertexArrays(
            5, [self.ball_vao, self.plane_vao, self.line_vao, self.ghost_vao, self.screen_vao]
        )
        GL.glDeleteBuffers(2, list(self.shadow_buffers))
        GL.glDeleteTextures(2, list(self.shadow_textures))
