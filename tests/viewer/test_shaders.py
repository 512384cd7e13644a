"""Shader loading: the bundled GLSL compiles; includes keep file/line mapping; errors name the file."""

from __future__ import annotations

import pytest

from ballpit.viewer.shaders import ShaderError, load_source, shader_dir

BUNDLED = (
    "ball.vert",
    "ball.frag",
    "plane.vert",
    "plane.frag",
    "line.vert",
    "line.frag",
    "common.glsl",
    "casters.glsl",
)


def test_the_bundled_shaders_ship_in_the_shader_directory():
    directory = shader_dir()
    for name in BUNDLED:
        assert (directory / name).is_file(), name
        assert "#version 330 core" in (directory / name).read_text() or name.endswith(".glsl")


def test_includes_are_spliced_with_line_directives(tmp_path):
    (tmp_path / "main.frag").write_text('#version 330 core\n#include "lib.glsl"\nvoid main() {}\n')
    (tmp_path / "lib.glsl").write_text("float helper() { return 1.0; }\n")
    source, files = load_source("main.frag", tmp_path)
    assert files == ["main.frag", "lib.glsl"]
    lines = source.splitlines()
    assert lines[:5] == ["#version 330 core", "#line 1 1", "float helper() { return 1.0; }", "", "#line 3 0"]


def test_a_missing_shader_file_is_named(tmp_path):
    with pytest.raises(ShaderError, match=r"nope\.frag"):
        load_source("nope.frag", tmp_path)


def test_a_compile_error_names_the_shader_file_and_quotes_the_driver_log(offscreen, tmp_path):
    from ballpit.viewer.shaders import Program

    (tmp_path / "broken.vert").write_text("#version 330 core\nvoid main() { gl_Position = vec4(1.0) }\n")
    (tmp_path / "line.frag").write_text((shader_dir() / "line.frag").read_text())
    with pytest.raises(ShaderError) as info:
        Program("broken.vert", "line.frag", tmp_path)
    message = str(info.value)
    assert "broken.vert" in message and "failed to compile" in message
    assert "error" in message.lower() and "0:2" in message  # the driver's log, pointing at line 2


def test_an_error_inside_an_include_is_reported_against_the_included_file(offscreen, tmp_path):
    from ballpit.viewer.shaders import Program

    (tmp_path / "ok.vert").write_text((shader_dir() / "line.vert").read_text())
    (tmp_path / "bad.frag").write_text(
        '#version 330 core\n#include "lib.glsl"\nout vec4 c;\nvoid main() { c = vec4(f()); }\n'
    )
    (tmp_path / "lib.glsl").write_text("float f() {\n  return undefined_name;\n}\n")
    with pytest.raises(ShaderError) as info:
        Program("ok.vert", "bad.frag", tmp_path)
    message = str(info.value)
    assert "bad.frag" in message and "1 = lib.glsl" in message
    assert "1:2" in message  # source string 1 (lib.glsl), line 2


def test_a_link_error_names_both_shaders(offscreen, tmp_path):
    from ballpit.viewer.shaders import Program

    (tmp_path / "a.vert").write_text("#version 330 core\nvoid main() { gl_Position = vec4(0); }\n")
    (tmp_path / "b.frag").write_text(
        "#version 330 core\nout vec4 c;\nvoid shade() { c = vec4(1); }\n"
    )  # no main
    with pytest.raises(ShaderError, match=r"a\.vert \+ b\.frag failed to link"):
        Program("a.vert", "b.frag", tmp_path)


def test_a_uniform_already_holding_the_value_set_is_not_sent_again_and_a_new_value_is(offscreen):
    import numpy as np
    from OpenGL import GL

    from ballpit.viewer.shaders import Program

    program = Program("line.vert", "line.frag")
    program.use()
    loc = program.location("u_view_projection")
    first = np.arange(16, dtype=np.float32).reshape(4, 4)
    program.set("u_view_projection", first)
    program.set("u_view_projection", first.copy())  # the same value: not sent
    assert program.uniform_calls == 1
    second = first + 0.5
    program.set("u_view_projection", second)
    assert program.uniform_calls == 2
    held = np.zeros(16, dtype=np.float32)
    GL.glGetUniformfv(program.id, loc, held)
    assert np.array_equal(held.reshape(4, 4), second)  # GL holds the value set last
    program.set("u_view_projection", first)  # back to an earlier value: sent, as GL holds another
    GL.glGetUniformfv(program.id, loc, held)
    assert program.uniform_calls == 3 and np.array_equal(held.reshape(4, 4), first)
    GL.glUseProgram(0)
    program.delete()


def test_defines_go_after_the_version_line_and_keep_the_line_numbers(tmp_path):
    (tmp_path / "main.frag").write_text("#version 330 core\nvoid main() {}\n")
    source, _ = load_source("main.frag", tmp_path, {"CASTERS": 3})
    assert source.splitlines()[:4] == [
        "#version 330 core",
        "#define CASTERS 3",
        "#line 2 0",
        "void main() {}",
    ]
