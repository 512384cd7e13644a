"""The viewer: a pyglet window with instanced OpenGL 3.3 rendering, and offscreen rendering to MP4/GIF/PNG.

Entry points (imported lazily by the CLI): ``ballpit.viewer.app.run(scene_path)`` opens the window;
``ballpit.viewer.render.render(scene_path, out, ...)`` renders headless through EGL. A process uses
one or the other (see ``backend``). Nothing is imported here so ``import ballpit.viewer`` stays free of
GL: ``controls``, ``camera``, ``simulation`` and ``overlays`` are pure Python/NumPy. A scene's look
(camera start, colours) comes from ``ballpit.scene``.
"""
