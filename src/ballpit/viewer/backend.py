"""Choosing the GL platform (a real window or headless EGL) before pyglet and PyOpenGL are imported.

pyglet fixes its platform when ``pyglet.window`` is first imported (``pyglet.options['headless']``), and
PyOpenGL fixes its function loader when ``OpenGL.GL`` is first imported (``PYOPENGL_PLATFORM``). The two
must agree, and neither can change afterwards, so a process is either a window process or a headless
one. Every module that imports ``pyglet.window``/``OpenGL.GL`` at its top is imported only after
``use_window()`` or ``use_headless()`` has run.
"""

from __future__ import annotations

import os
import sys


class BackendError(RuntimeError):
    """The process already chose the other GL platform."""


def current_mode() -> str | None:
    """ "headless" or "window" once pyglet's window module is imported, else None (still free to choose)."""
    if "pyglet.window" not in sys.modules:
        return None
    import pyglet

    return "headless" if pyglet.options["headless"] else "window"


def use_headless() -> None:
    """Render offscreen through EGL: no display needed. Call before importing any GL module."""
    _select("headless")


def use_window() -> None:
    """Open real windows (X11/GLX on Linux). Call before importing any GL module."""
    leave_a_core_to_the_physics()
    _select("window")


def leave_a_core_to_the_physics() -> None:
    """Ask Mesa's llvmpipe for one rasteriser thread fewer than the cores this process may use.

    llvmpipe rasterises each frame on ``LP_NUM_THREADS`` threads, by default one per core, so on two
    cores a frame briefly takes the core the physics thread steps on as well (three threads wanting two
    cores). With one fewer, the window's thread waits for the rasteriser while it draws and the physics
    keeps its core. Mesa reads the variable when the first GL context is made, so this runs before the
    window opens; a value already set is kept, and a GPU's driver ignores it.
    """
    if "LP_NUM_THREADS" in os.environ or not hasattr(os, "sched_getaffinity"):
        return
    os.environ["LP_NUM_THREADS"] = str(max(len(os.sched_getaffinity(0)) - 1, 1))


def _select(mode: str) -> None:
    chosen = current_mode()
    if chosen is not None and chosen != mode:
        raise BackendError(
            f"this process already uses pyglet in {chosen} mode and cannot switch to {mode} mode; "
            "run the viewer and offscreen rendering in separate processes"
        )
    _check_pyopengl(mode)
    if "OpenGL.GL" not in sys.modules:
        if mode == "headless":
            os.environ["PYOPENGL_PLATFORM"] = "egl"
        elif sys.platform.startswith(("linux", "freebsd", "openbsd")):
            # pyglet windows use GLX there; PyOpenGL must load its functions the same way (it would pick
            # EGL on a Wayland session, which does not match pyglet's XWayland/GLX context).
            os.environ["PYOPENGL_PLATFORM"] = "glx"
    import pyglet

    if chosen is None:
        pyglet.options["headless"] = mode == "headless"
        # The shadow window only helps share objects between windows; ballpit opens one.
        pyglet.options["shadow_window"] = False


def _check_pyopengl(mode: str) -> None:
    """PyOpenGL imported before the mode was chosen may have picked the wrong loader: say so clearly."""
    if "OpenGL.platform" not in sys.modules:
        return
    platform = type(sys.modules["OpenGL.platform"].PLATFORM).__name__  # e.g. EGLPlatform, GLXPlatform
    wanted = {"headless": "EGL"}.get(mode) or ("GLX" if sys.platform.startswith("linux") else None)
    if wanted is not None and not platform.startswith(wanted):
        raise BackendError(
            f"PyOpenGL was imported with the {platform} loader before ballpit chose {mode} mode (which needs "
            f"{wanted}); import ballpit.viewer before OpenGL, or set PYOPENGL_PLATFORM={wanted.lower()}"
        )


def display_problem() -> str | None:
    """Why no window can be opened here (no X display), or None if one may be. Imports nothing."""
    if sys.platform.startswith(("linux", "freebsd", "openbsd")) and not os.environ.get("DISPLAY"):
        return "DISPLAY is not set"
    return None


def no_display_message(reason: str) -> str:
    """The one line printed when the viewer cannot open a window."""
    return (
        f"ballpit: no display to open the viewer on ({reason}); render offscreen instead with "
        "`ballpit render SCENE --out demo.gif`, or run under a virtual display with `xvfb-run ballpit`"
    )
