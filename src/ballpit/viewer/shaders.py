"""Loading GLSL from the ``shaders/`` directory (package ``ballpit.shaders``), compiling and linking it.

Sources may pull in shared code with ``#include "name.glsl"``; the loader splices the file in between
``#line`` directives so the driver's log still points at the right file and line (GLSL numbers source
strings: 0 is the main file, 1, 2, ... the includes in order). A program may be compiled with
``defines`` (``#define NAME VALUE`` lines after ``#version``), such as how many shadow casters to
unroll. Compile and link failures raise ``ShaderError`` naming the file and quoting the driver's log.
"""

from __future__ import annotations

import re
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path

import numpy as np

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$')


class ShaderError(RuntimeError):
    """A shader failed to load, compile or link."""


def shader_dir() -> Traversable:
    """Where the GLSL files live: the installed ``ballpit.shaders`` package, or the source checkout's
    ``shaders/`` (an editable install cannot import a namespace package inside a regular one)."""
    try:
        return resources.files("ballpit.shaders")
    except ModuleNotFoundError:
        checkout = Path(__file__).resolve().parents[3] / "shaders"
        if checkout.is_dir():
            return checkout
        raise ShaderError(
            f"cannot find the ballpit shaders (no package ballpit.shaders, no {checkout})"
        ) from None


def load_source(
    name: str, directory: Traversable | Path | None = None, defines: dict[str, int] | None = None
) -> tuple[str, list[str]]:
    """The text of shader ``name`` with its includes spliced in, and the file names by source-string
    number (index 0 is ``name``); ``defines`` go after its first line (``#version``)."""
    directory = shader_dir() if directory is None else directory
    files: list[str] = [name]

    def read(file: str) -> str:
        path = directory / file
        try:
            return path.read_text(encoding="utf-8")
        except (FileNotFoundError, OSError) as exc:
            raise ShaderError(f"cannot read shader {file} from {directory}: {exc}") from None

    def expand(file: str, number: int) -> str:
        out: list[str] = []
        for lineno, line in enumerate(read(file).splitlines(), start=1):
            if number == 0 and lineno == 2 and defines:
                out.extend(f"#define {key} {value}" for key, value in defines.items())
                out.append(f"#line 2 {number}")
            match = _INCLUDE.match(line)
            if match is None:
                out.append(line)
                continue
            included = match.group(1)
            files.append(included)
            out.append(f"#line 1 {len(files) - 1}")
            out.append(expand(included, len(files) - 1))
            out.append(f"#line {lineno + 1} {number}")
        return "\n".join(out) + "\n"

    return expand(name, 0), files


def _describe_sources(files: list[str]) -> str:
    if len(files) == 1:
        return ""
    return " (source strings: " + ", ".join(f"{i} = {f}" for i, f in enumerate(files)) + ")"


def compile_shader(
    name: str, directory: Traversable | Path | None = None, defines: dict[str, int] | None = None
) -> int:
    """Compile one shader file (its stage from the suffix: .vert or .frag); returns the GL name."""
    from OpenGL import GL

    stages = {".vert": GL.GL_VERTEX_SHADER, ".frag": GL.GL_FRAGMENT_SHADER}
    suffix = Path(name).suffix
    if suffix not in stages:
        raise ShaderError(f"{name}: unknown shader stage (expected .vert or .frag)")
    source, files = load_source(name, directory, defines)
    shader = GL.glCreateShader(stages[suffix])
    GL.glShaderSource(shader, source)
    GL.glCompileShader(shader)
    if not GL.glGetShaderiv(shader, GL.GL_COMPILE_STATUS):
        log = GL.glGetShaderInfoLog(shader)
        log = log.decode(errors="replace") if isinstance(log, bytes) else str(log)
        GL.glDeleteShader(shader)
        raise ShaderError(f"shader {name} failed to compile{_describe_sources(files)}:\n{log.strip()}")
    return shader


class Program:
    """A linked vertex + fragment program with cached uniform locations.

    A uniform keeps its value in the program between frames, so a ``set`` of the value it already
    holds is skipped: most of a frame's uniforms (fog, sun, the shadow casters) are the same every
    frame, and each GL call through PyOpenGL costs the window's thread tens of microseconds of Python.
    """

    def __init__(
        self,
        vertex: str,
        fragment: str,
        directory: Traversable | Path | None = None,
        defines: dict[str, int] | None = None,
    ) -> None:
        from OpenGL import GL

        self.name = f"{vertex} + {fragment}"
        shaders = [compile_shader(vertex, directory, defines), compile_shader(fragment, directory, defines)]
        program = GL.glCreateProgram()
        for shader in shaders:
            GL.glAttachShader(program, shader)
        GL.glLinkProgram(program)
        for shader in shaders:
            GL.glDetachShader(program, shader)
            GL.glDeleteShader(shader)
        if not GL.glGetProgramiv(program, GL.GL_LINK_STATUS):
            log = GL.glGetProgramInfoLog(program)
            log = log.decode(errors="replace") if isinstance(log, bytes) else str(log)
            GL.glDeleteProgram(program)
            raise ShaderError(f"shader program {self.name} failed to link:\n{log.strip()}")
        self.id = program
        self._gl = GL
        self._locations: dict[str, int] = {}
        self._values: dict[int, bytes | int] = {}  # the value each uniform location holds, as set last
        self.uniform_calls = 0  # uniforms sent to GL (a set of the value held is not sent)

    def use(self) -> None:
        self._gl.glUseProgram(self.id)

    def location(self, uniform: str) -> int:
        loc = self._locations.get(uniform)
        if loc is None:
            loc = self._locations[uniform] = self._gl.glGetUniformLocation(self.id, uniform)
        return loc

    def _changed(self, loc: int, value: bytes | int) -> bool:
        """Whether uniform ``loc`` needs ``value`` sent (it holds another); remembers it as held."""
        if loc < 0 or self._values.get(loc) == value:
            return False
        self._values[loc] = value
        self.uniform_calls += 1
        return True

    def set(self, uniform: str, value: object) -> None:
        """Set a float, vec2/3/4 or mat4 uniform from a number or array (the program must be in use)."""
        GL = self._gl
        loc = self.location(uniform)
        arr = np.asarray(value, dtype=np.float32)
        if not self._changed(loc, arr.tobytes()):
            return  # optimised away by the driver, or holding this value already
        if arr.shape == (4, 4):
            GL.glUniformMatrix4fv(loc, 1, GL.GL_FALSE, np.ascontiguousarray(arr))
        elif arr.ndim == 0:
            GL.glUniform1f(loc, float(arr))
        else:
            setter = {2: GL.glUniform2fv, 3: GL.glUniform3fv, 4: GL.glUniform4fv}[arr.shape[-1]]
            setter(loc, 1, arr)

    def set_array(self, uniform: str, values: np.ndarray) -> None:
        """Set a uniform array of vec2 or vec3 from a (K, 2) or (K, 3) array."""
        GL = self._gl
        loc = self.location(uniform)
        arr = np.ascontiguousarray(values, dtype=np.float32)
        if len(arr) and self._changed(loc, arr.tobytes()):
            setter = {2: GL.glUniform2fv, 3: GL.glUniform3fv}[arr.shape[-1]]
            setter(loc, len(arr), arr)

    def set_int_array(self, uniform: str, values: np.ndarray) -> None:
        """Set a uniform int array."""
        loc = self.location(uniform)
        arr = np.ascontiguousarray(values, dtype=np.int32)
        if len(arr) and self._changed(loc, b"i" + arr.tobytes()):
            self._gl.glUniform1iv(loc, len(arr), arr)

    def set_int(self, uniform: str, value: int) -> None:
        """Set an int uniform, such as the texture unit a sampler reads (the program must be in use)."""
        loc = self.location(uniform)
        if self._changed(loc, int(value)):
            self._gl.glUniform1i(loc, int(value))

    def delete(self) -> None:
        self._gl.glDeleteProgram(self.id)
