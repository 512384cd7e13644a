"""The panel: a Dear ImGui window docked at the left of the viewer (F4 hides and shows it).

Sections, as in Box2D's samples and MuJoCo's ``simulate``: Scenes, Simulation, Inspector, Plots (ImPlot),
View and Record video. Every widget is a thin view of what the physics side handed over (``Shown.watch``,
watch.py) and acts in one of two ways only: a button of an action runs ``Viewer.perform`` (the same
handler as its key, actions.py), and an edit goes to the physics side as a command (edits.py). Nothing
here touches the World.

The window keeps each widget's rectangle of the last frame (``rects``, window pixels, y down), so the
window tests click at the widgets' real places.
"""

from __future__ import annotations

import shutil
import time
from collections import deque
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from imgui_bundle import ImVec2, ImVec4, imgui, implot

from ..physics.dynamics.integrators import INTEGRATORS
from ..scene import bundled_scenes
from . import actions
from .controls import Action, IntegratorAction
from .edits import AT_ONCE, ON_RESET, Edits
from .energyplot import KINETIC_COLOR, POTENTIAL_COLOR
from .ghosts import LABELS, TINTS
from .panel_backend import PanelBackend
from .simulation import Phase
from .video import REC_COLOR
from .watch import BallFacts, PlaneFacts, Watch

if TYPE_CHECKING:
    from .app import Viewer
    from .handover import Shown

WIDTH = 330  # px, the panel's width
PROMPT = "press X or click Drop"
PROMPT_SIZE = 40.0  # px, the first minute's prompt
ERROR = ImVec4(1.0, 0.45, 0.4, 1.0)
MUTED = ImVec4(0.65, 0.68, 0.75, 1.0)
REC = ImVec4(*(c / 255 for c in REC_COLOR))  # the recording mark, as the window's
PLOT_HEIGHT = 200
RECENT_LIMIT = 8
DIALOG_TOOLS = ("zenity", "kdialog", "matedialog", "qarma")  # what portable_file_dialogs runs on Linux
PLOTS = ("energy", "ball", "contacts", "stages")
LEGEND = implot.LegendFlags_.outside | implot.LegendFlags_.horizontal  # never over the curves
KINETIC, POTENTIAL = ImVec4(*KINETIC_COLOR), ImVec4(*POTENTIAL_COLOR)


def has_file_dialog() -> bool:
    """Whether "Open…" can show the desktop's file dialog (else the panel takes a typed path)."""
    return any(shutil.which(tool) for tool in DIALOG_TOOLS)


def _spec(color: object, weight: float = 1.5) -> implot.Spec:
    spec = implot.Spec()
    spec.line_color = ImVec4(*color) if not isinstance(color, ImVec4) else color
    spec.line_weight = weight
    return spec


def apexes(time: np.ndarray, height: np.ndarray) -> np.ndarray:
    """Indices of the local maxima of a height series (a bounce's apexes: e²·h apart)."""
    if len(height) < 3:
        return np.zeros(0, dtype=int)
    h = np.nan_to_num(height, nan=-np.inf)
    inner = (h[1:-1] > h[:-2]) & (h[1:-1] >= h[2:])
    return np.flatnonzero(inner) + 1


class Panel:
    """The ImGui panel of one Viewer: drawn by ``draw`` each frame after the 3-D view and the HUD."""

    def __init__(self, viewer: Viewer) -> None:
        self.viewer = viewer
        self.backend = PanelBackend(viewer.window)
        self.shown = True
        # The panel's background, ImGui's own window colour: the window clears the strip under the panel
        # to it (framebuffer.WindowView), and ImGui does not fill it again (a blended fill of a third of
        # a million pixels cost a CPU rasteriser about 2 ms a frame; the clear a fraction of that).
        bg = imgui.get_style().color_(imgui.Col_.window_bg)
        self.background = (bg.x, bg.y, bg.z)
        self.edits = Edits(viewer.physics.submit)
        self.plots = dict.fromkeys(PLOTS, False) | {"energy": True, "ball": True}
        self.sections = {"Scenes": True, "Simulation": True, "Inspector": True, "Plots": False, "View": False}
        self._reopen: set[str] = set()  # sections to open at the next frame (P, F2)
        self.recent: deque[Path] = deque(maxlen=RECENT_LIMIT)
        self.rects: dict[str, tuple[float, float, float, float]] = {}
        self.adding_ball = False  # the next click on a surface adds a ball there
        self.path_text = ""
        self._dialog: object = None
        self._dialog_kind = ""
        # building and drawing the panel, per frame: wall time, and the window thread's own CPU time (the
        # wall time also holds the waits for the GIL and for a core while the physics thread runs)
        self.seconds: deque[float] = deque(maxlen=240)
        self.cpu_seconds: deque[float] = deque(maxlen=240)
        self._rebuilt = True  # the last ``build`` laid the panel out anew (else its last build is drawn)
        self._spent = (0.0, 0.0)  # wall and thread time the last build took
        self._window = (0.0, 0.0, 0.0, 0.0)
        self._bundled = [path.resolve() for path in bundled_scenes()]
        self._prompt_key: tuple = ()
        self._prompt_y = 0.0
        self._path: object = None  # the scene file shown, and its resolved path
        self._current: Path | None = None

    # ------------------------------------------------------------------ what the window asks
    @property
    def width(self) -> int:
        """Pixels the panel covers at the left (0 while hidden)."""
        return WIDTH if self.shown else 0

    def covers(self, x: float, y: float) -> bool:
        """Whether window point (x, y) (y up) is on the panel, or ImGui holds the mouse (a drag that
        started on a widget)."""
        if not self.shown:
            return False
        wx, wy, ww, wh = self._window
        top = self.viewer.window.height - y
        return (wx <= x <= wx + ww and wy <= top <= wy + wh) or self.backend.wants_mouse

    @property
    def wants_keyboard(self) -> bool:
        return self.shown and self.backend.wants_keyboard

    def plot_open(self, name: str) -> bool:
        return self.shown and self.plots[name] and self.sections["Plots"]

    def open_plot(self, name: str, on: bool) -> None:
        """P / F2: show (or hide) one plot, opening the panel and its Plots section to show it."""
        self.plots[name] = on
        if on:
            self.shown = True
            self.sections["Plots"] = True
            self._reopen.add("Plots")

    @property
    def wants_plots(self) -> bool:
        """Whether the physics side should copy the traces at hand-over."""
        return self.shown and self.sections["Plots"] and any(self.plots.values())

    def cost_ms(self, cpu: bool = False) -> float:
        """The mean time the panel took to build and draw over the recent frames, ms (``cpu``: the
        window thread's CPU time)."""
        kept = self.cpu_seconds if cpu else self.seconds
        return 1e3 * float(np.mean(kept)) if kept else 0.0

    # ------------------------------------------------------------------ the frame
    def build(self, shown: Shown, rebuild: bool = True) -> None:
        """Lay the panel out for ``shown`` (ImGui's widgets, Python on the window's thread), for
        ``render`` to draw: the window builds it while the rasteriser draws the 3-D view. Without
        ``rebuild`` and with no input since, the last build is kept (the window's frames while the
        physics is busy: pacing.py)."""
        started, cpu = time.perf_counter(), time.thread_time()
        self._rebuilt = rebuild or not self.backend.can_redraw()
        if self._rebuilt:
            self.backend.new_frame()
            watch: Watch | None = shown.watch
            if self.shown and watch is not None:
                self._panel(shown, watch)
            else:
                self._window = (0.0, 0.0, 0.0, 0.0)
            if watch is not None and watch.world.phase is Phase.WAITING and not watch.world.replay:
                self._prompt(shown)
            self._poll_dialog()
        self._spent = (time.perf_counter() - started, time.thread_time() - cpu)

    def render(self) -> None:
        """Draw what ``build`` laid out (or its last build again) into the window."""
        started, cpu = time.perf_counter(), time.thread_time()
        if self._rebuilt:
            self.backend.render()
        else:
            self.backend.redraw()
        wall, thread = self._spent
        self.seconds.append(wall + time.perf_counter() - started)
        self.cpu_seconds.append(thread + time.thread_time() - cpu)

    def _remember(self, key: str) -> None:
        lo, hi = imgui.get_item_rect_min(), imgui.get_item_rect_max()
        self.rects[key] = (lo.x, lo.y, hi.x - lo.x, hi.y - lo.y)

    def _prompt(self, shown: Shown) -> None:
        """The first minute: a large "press X or click Drop", centred across the 3-D view, at the
        height nearest the middle where it covers no ball."""
        w = self.viewer.window.width
        left = self.width
        draw = imgui.get_foreground_draw_list()
        font = imgui.get_font()
        size = imgui.calc_text_size(PROMPT)
        scale = PROMPT_SIZE / imgui.get_font_size()
        tw, th = size.x * scale, size.y * scale
        x = left + (w - left - tw) / 2
        y = self._prompt_height(shown, x, tw, th)
        draw.add_rect_filled(
            ImVec2(x - 18, y - 10),
            ImVec2(x + tw + 18, y + th + 10),
            imgui.get_color_u32(ImVec4(0.04, 0.05, 0.07, 0.72)),
            10.0,
        )
        draw.add_text(font, PROMPT_SIZE, ImVec2(x, y), imgui.get_color_u32(ImVec4(1, 1, 1, 1)), PROMPT)
        self.rects["prompt"] = (x, y, tw, th)

    def _prompt_height(self, shown: Shown, x: float, tw: float, th: float) -> float:
        """The top of the prompt: the first of some heights, from the middle outwards, whose band
        (padded) holds no ball as drawn; the middle if every one does. Worked out again only when the
        balls or the camera change."""
        camera = self.viewer.camera
        w, h = self.viewer.window.width, self.viewer.window.height
        key = (id(shown), tuple(camera.position), camera.yaw, camera.pitch, camera.inset, w, h)
        if key == self._prompt_key:
            return self._prompt_y
        pixels, depth = camera.project(shown.positions, w, h) if shown.ball_count else (np.zeros((0, 2)), [])
        self._prompt_key, self._prompt_y = key, h * 0.5 - th / 2
        front = np.asarray(depth) > 0
        px = pixels[front]
        for share in (0.5, 0.35, 0.65, 0.2, 0.8, 0.1, 0.9):
            top = h * share - th / 2
            inside = (
                (px[:, 0] > x - 40)
                & (px[:, 0] < x + tw + 40)
                & (px[:, 1] > top - 30)
                & (px[:, 1] < top + th + 30)
            )
            if not inside.any():
                self._prompt_y = top
                break
        return self._prompt_y

    def _panel(self, shown: Shown, watch: Watch) -> None:
        h = self.viewer.window.height
        imgui.set_next_window_pos(ImVec2(0, 0))
        imgui.set_next_window_size(ImVec2(WIDTH, h))
        imgui.set_next_window_bg_alpha(0.0)  # the strip under it is cleared to ``background``
        flags = (
            imgui.WindowFlags_.no_move
            | imgui.WindowFlags_.no_resize
            | imgui.WindowFlags_.no_collapse
            | imgui.WindowFlags_.no_saved_settings
        )
        imgui.begin("ballpit (F4 hides)", None, flags)
        pos, size = imgui.get_window_pos(), imgui.get_window_size()
        self._window = (pos.x, pos.y, size.x, size.y)
        imgui.push_item_width(-130)
        for name, body in (
            ("Scenes", self._scenes),
            ("Simulation", self._simulation),
            ("Inspector", self._inspector),
            ("Plots", self._plots),
            ("View", self._view),
            ("Record video", self._record),
        ):
            reopened = name in self._reopen
            if reopened:
                imgui.set_next_item_open(True)
                self._reopen.discard(name)
            elif name in self.sections:
                imgui.set_next_item_open(self.sections[name], imgui.Cond_.once)
            opened = imgui.collapsing_header(name)
            if reopened:  # opened by its key (P, F2): scrolled to the top of the panel
                imgui.set_scroll_here_y(0.0)
            self._remember(f"section {name}")
            if name in self.sections:
                self.sections[name] = opened
            if opened:
                imgui.push_id(name)
                body(shown, watch)
                imgui.pop_id()
        imgui.pop_item_width()
        imgui.end()

    # ------------------------------------------------------------------ widgets
    def _action_button(self, action: object, text: str, key: str | None = None) -> bool:
        """A button that runs ``action``, labelled ``text`` and its keys; ``key`` names a button whose
        text changes (Pause / Resume) with one ImGui id and one place in ``rects``."""
        clicked = imgui.button(actions.label(action, text) + (f"###{key}" if key else ""))
        self._remember(key or text)
        if imgui.is_item_hovered():
            imgui.set_tooltip(str(action.value))
        if clicked:
            self.viewer.perform(action)
        return clicked

    def _error(self, key: str) -> None:
        """The error of a refused edit, in red under its widget (until an edit of it succeeds)."""
        error = self.edits.error(key)
        if error:
            imgui.push_text_wrap_pos(0.0)
            imgui.text_colored(ERROR, error)
            imgui.pop_text_wrap_pos()
            self._remember(f"error {key}")

    def _number(self, label: str, key: str, value: float, send, fmt: str = "%.4g") -> None:
        """A typed number, sent when the field is left or Enter pressed (a refusal shows below it)."""
        _, typed = imgui.input_double(label, float(value), 0.0, 0.0, fmt)
        self._remember(key)
        if imgui.is_item_deactivated_after_edit():
            send(typed)
        self._error(key)

    def _vector(self, label: str, key: str, value: object, send, fmt: str = "%.3f") -> None:
        _, typed = imgui.input_float3(label, [float(v) for v in value], fmt)
        self._remember(key)
        if imgui.is_item_deactivated_after_edit():  # ImGui's fields hold 32-bit floats: send what was typed
            send(tuple(float(f"{v:.7g}") for v in typed))
        self._error(key)

    # ------------------------------------------------------------------ Scenes
    def _scenes(self, shown: Shown, watch: Watch) -> None:
        if watch.world.path != self._path:  # resolved once per scene, not every frame
            self._path = watch.world.path
            self._current = Path(self._path).resolve() if self._path else None
        imgui.text_colored(MUTED, "bundled scenes: one click opens")
        for path in self._bundled:
            picked, _ = imgui.selectable(path.stem, self._current == path)
            self._remember(f"scene {path.stem}")
            if picked:
                self.open_scene(path)
        if imgui.button("Open…"):
            self._open_dialog()
        self._remember("Open")
        imgui.same_line()
        self._action_button(Action.RELOAD, "Reload")
        imgui.same_line()
        self._action_button(Action.SAVE, "Save")
        if imgui.button("Save as…"):
            self._save_dialog()
        self._remember("Save as")
        imgui.text_colored(MUTED, "or type a path (Enter opens; drop a .toml on the window):")
        entered, self.path_text = imgui.input_text(
            "##path", self.path_text, imgui.InputTextFlags_.enter_returns_true
        )
        self._remember("path")
        if entered and self.path_text.strip():
            self.open_scene(Path(self.path_text.strip()).expanduser())
        self._error("scene")
        self._error("save")
        if shown.error:
            imgui.push_text_wrap_pos(0.0)
            imgui.text_colored(ERROR, shown.error)
            imgui.pop_text_wrap_pos()
        if self.recent:
            imgui.text_colored(MUTED, "recent")
            for path in list(self.recent):
                if imgui.selectable(f"{path.name}##recent {path}", False)[0]:
                    self.open_scene(path)
                self._remember(f"recent {path.name}")
                if imgui.is_item_hovered():
                    imgui.set_tooltip(str(path))

    def open_scene(self, path: Path) -> None:
        """Open a scene file (a bundled one, a typed or dropped path, a recent one): the physics side
        loads it; a file that is not a valid scene keeps the current one and its error shows here."""
        path = Path(path)

        def opened(result: object) -> None:
            self.remember_recent(path)
            self.viewer.scene_opened()

        self.edits.open_scene(path, opened)

    def remember_recent(self, path: Path) -> None:
        path = Path(path).resolve()
        if path in self.recent:
            self.recent.remove(path)
        self.recent.appendleft(path)

    def _open_dialog(self) -> None:
        if not has_file_dialog():
            self.edits.errors["scene"] = "no file dialog here (zenity or kdialog): type the path below"
            return
        from imgui_bundle import portable_file_dialogs as pfd

        self._dialog = pfd.open_file("Open a ballpit scene", str(Path.cwd()), ["Scene files", "*.toml"])
        self._dialog_kind = "open"

    def _save_dialog(self) -> None:
        if not has_file_dialog():
            typed = self.path_text.strip()
            if not typed:
                self.edits.errors["save"] = (
                    "no file dialog here: type the new file's path above, then Save as"
                )
                return
            self.viewer.save_scene(Path(typed).expanduser())
            return
        from imgui_bundle import portable_file_dialogs as pfd

        self._dialog = pfd.save_file("Save the scene as", str(Path.cwd()), ["Scene files", "*.toml"])
        self._dialog_kind = "save"

    def _poll_dialog(self) -> None:
        dialog = self._dialog
        if dialog is None or not dialog.ready(0):
            return
        self._dialog = None
        result = dialog.result()
        if self._dialog_kind == "open" and result:
            self.open_scene(Path(result[0]))
        elif self._dialog_kind == "save" and result:
            self.viewer.save_scene(Path(result))

    # ------------------------------------------------------------------ Simulation
    def _simulation(self, shown: Shown, watch: Watch) -> None:
        w = watch.world
        self._action_button(Action.START, "Drop")
        imgui.same_line()
        self._action_button(Action.PAUSE, "Resume" if w.phase is Phase.PAUSED else "Pause", key="Pause")
        imgui.same_line()
        self._action_button(Action.RESET, "Reset")
        self._action_button(Action.STEP_BACK, "Step back")
        imgui.same_line()
        self._action_button(Action.STEP, "Step")
        imgui.text(f"t = {w.time:.3f} s   {w.phase.value.split(':')[0]}")
        changed, scale = imgui.slider_float(
            "time scale", w.time_scale, 1 / 64, 8.0, "×%.3g", imgui.SliderFlags_.logarithmic
        )
        self._remember("time scale")
        if changed:
            self.edits.world("time_scale", scale)
        names = list(INTEGRATORS)
        changed, k = imgui.combo(
            "integrator", names.index(w.integrator), [INTEGRATORS[n].label for n in names]
        )
        self._remember("integrator")
        if changed:
            self.viewer.perform(IntegratorAction[names[k].upper()])
        self._number(
            "timestep ms", "world.timestep", w.timestep * 1e3, lambda v: self.edits.world("timestep", v / 1e3)
        )
        _, substeps = imgui.input_int("substeps", w.substeps)
        self._remember("world.substeps")
        if imgui.is_item_deactivated_after_edit() or (substeps != w.substeps and not imgui.is_item_active()):
            self.edits.world("substeps", substeps)
        self._error("world.substeps")
        self._vector("gravity", "world.gravity", w.gravity, lambda v: self.edits.world("gravity", v), "%.3g")
        changed, sleep = imgui.checkbox("sleep", w.sleep)
        self._remember("world.sleep")
        if changed:
            self.edits.world("sleep", sleep)
        automatic = w.restitution_threshold is None
        changed, automatic = imgui.checkbox("automatic##threshold", automatic)
        self._remember("world.threshold_auto")
        if changed:
            self.edits.world("restitution_threshold", None if automatic else w.threshold_used)
        imgui.same_line()
        if automatic:
            imgui.text(f"threshold {w.threshold_used:.3g} m/s")
        else:
            self._number(
                "threshold m/s",
                "world.restitution_threshold",
                w.restitution_threshold,
                lambda v: self.edits.world("restitution_threshold", v),
            )
        self._error("world.time_scale")
        self._error("world.sleep")
        imgui.push_text_wrap_pos(0.0)
        at_once = ", ".join(AT_ONCE).replace("_", " ")
        imgui.text_colored(
            MUTED,
            f"At once (and kept by Reset): {at_once}. On reset: {', '.join(ON_RESET)} "
            "(changing it resets the run).",
        )
        imgui.pop_text_wrap_pos()

    # ------------------------------------------------------------------ Inspector
    def _inspector(self, shown: Shown, watch: Watch) -> None:
        s = watch.selected
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(
            MUTED,
            "Click a ball or a plane to select it; drag a ball to pull it; double-click a ball to orbit it.",
        )
        imgui.pop_text_wrap_pos()
        _, self.adding_ball = imgui.checkbox("add a ball where I click", self.adding_ball)
        self._remember("add ball")
        self._error("add")
        if isinstance(s, BallFacts):
            self._ball(s)
        elif isinstance(s, PlaneFacts):
            self._plane(s)
        else:
            imgui.text("nothing selected")

    def _ball(self, b: BallFacts) -> None:
        i = b.index
        speed = float(np.sqrt((b.velocity * b.velocity).sum()))
        imgui.text(f"ball {i}   {b.contacts} contacts")
        imgui.text("position  " + "  ".join(f"{v:7.3f}" for v in b.position))
        imgui.text(f"speed {speed:.3f} m/s   spin {np.sqrt((b.spin * b.spin).sum()):.3f} rad/s")
        imgui.text(f"kinetic {b.kinetic:.4g} J   potential {b.potential:.4g} J")
        self._numbers("ball", b, ("radius", "mass", "restitution", "friction", "rolling_friction"))
        self._vector("velocity", "ball.velocity", b.velocity, lambda v: self.edits.ball(i, "velocity", v))
        if imgui.button("Delete ball"):
            self.edits.remove_ball(i, lambda _: self.viewer.select(None))
        self._remember("Delete ball")
        self._error("ball.remove")

    def _numbers(self, kind: str, facts: BallFacts | PlaneFacts, names: tuple[str, ...]) -> None:
        """One typed field per number ``names`` of the selected ball or plane."""
        edit = self.edits.ball if kind == "ball" else self.edits.plane
        for name in names:
            send = lambda v, n=name: edit(facts.index, n, v)  # noqa: E731
            self._number(name.replace("_", " "), f"{kind}.{name}", getattr(facts, name), send)

    def _plane(self, p: PlaneFacts) -> None:
        i = p.index
        size = "infinite" if p.size is None else f"{p.size[0]:g} × {p.size[1]:g} m"
        imgui.text(f"plane {i}   {size}")
        imgui.text("normal  " + "  ".join(f"{v:6.3f}" for v in p.normal))
        moving = np.any(p.velocity) or np.any(p.angular_velocity)
        imgui.text("moving" if moving else "still")
        self._vector("position", "plane.position", p.position, lambda v: self.edits.plane(i, "position", v))
        self._vector(
            "angles °", "plane.rotation", p.rotation, lambda v: self.edits.plane(i, "rotation", v), "%.2f"
        )
        self._numbers("plane", p, ("restitution", "friction", "rolling_friction"))
        self._vector("velocity", "plane.velocity", p.velocity, lambda v: self.edits.plane(i, "velocity", v))
        self._vector(
            "spin",
            "plane.angular_velocity",
            p.angular_velocity,
            lambda v: self.edits.plane(i, "angular_velocity", v),
        )

    # ------------------------------------------------------------------ Plots
    def _plots(self, shown: Shown, watch: Watch) -> None:
        for name, text in (
            ("energy", "energy (P)"),
            ("ball", "selected ball"),
            ("contacts", "contacts"),
            ("stages", "time per stage (F2)"),
        ):
            _, self.plots[name] = imgui.checkbox(text, self.plots[name])
            self._remember(f"plot {name}")
            if name in ("energy", "ball"):
                imgui.same_line()
        traces = watch.traces
        if traces is None:
            imgui.text_colored(MUTED, "(collecting)")
            return
        size = ImVec2(-1, PLOT_HEIGHT)
        fit = implot.AxisFlags_.auto_fit
        title = "energy: K kinetic, U potential"
        if self.plots["energy"] and traces.energy and implot.begin_plot(f"{title}##energy", size):
            self._remember("plot area energy")
            implot.setup_axes("t s", "J", fit, fit)
            implot.setup_legend(implot.Location_.north, LEGEND)
            e = traces.energy
            t = e["time"]
            implot.plot_line("K", t, e["kinetic"], _spec(KINETIC))
            implot.plot_line("U", t, e["potential"], _spec(POTENTIAL))
            totals = [key[6:] for key in e if key.startswith("total ")]
            main = watch.world.integrator
            for name in sorted(totals, key=lambda n: n == main):  # the run's own total on top
                label = LABELS.get(name, name) if len(totals) > 1 else "E"
                implot.plot_line(label, t, e[f"total {name}"], _spec((*TINTS[name], 1.0), 2.0))
            self._remember_legend("energy")
            implot.end_plot()
        if self.plots["ball"] and implot.begin_plot("selected ball", size):
            self._remember("plot area ball")
            implot.setup_axes("t s", "m, m/s", fit, fit)
            implot.setup_legend(implot.Location_.north, LEGEND)
            if traces.ball is not None and len(traces.time):
                implot.plot_line("height", traces.time, traces.height)
                implot.plot_line("speed", traces.time, traces.speed)
                top = apexes(traces.time, traces.height)
                if len(top):
                    spec = implot.Spec()
                    spec.marker = implot.Marker_.circle
                    implot.plot_scatter("apexes", traces.time[top], traces.height[top], spec)
            implot.end_plot()
        if self.plots["contacts"] and len(traces.time) and implot.begin_plot("contacts", size):
            implot.setup_axes("t s", "contacts", fit, fit)
            implot.plot_line("contacts", traces.time, traces.contacts)
            implot.end_plot()
        if self.plots["stages"] and traces.stages:
            imgui.text(f"step {traces.step_ms:.3f} ms (mean of the last half second)")
            names = list(traces.stages)
            if implot.begin_plot("ms per step", ImVec2(-1, 40 + 16 * len(names))):
                implot.setup_axes("ms", "", fit, fit)
                implot.setup_axis_ticks(implot.ImAxis_.y1, 0.0, len(names) - 1.0, len(names), names)
                spec = implot.Spec()
                spec.flags = implot.BarsFlags_.horizontal
                implot.plot_bars("stage", np.array(list(traces.stages.values())), 0.67, 0, spec)
                implot.end_plot()

    def _remember_legend(self, name: str) -> None:
        """Keep the plot's frame and its legend's rectangle as ImPlot laid them out (the last frame's),
        so the tests can check that the legend is not clipped."""
        plot = implot.internal.get_current_plot()
        for key, rect in ((f"frame {name}", plot.frame_rect), (f"legend {name}", plot.items.legend.rect)):
            self.rects[key] = (rect.min.x, rect.min.y, rect.get_width(), rect.get_height())

    # ------------------------------------------------------------------ View
    def _view(self, shown: Shown, watch: Watch) -> None:
        v = self.viewer
        toggles = (
            (Action.CONTACTS, "contacts", v.flags.contacts),
            (Action.VELOCITIES, "velocities", v.flags.velocities),
            (Action.TRAILS, "trails", v.flags.trails),
            (Action.HUD, "HUD", v.hud.show_hud),
            (Action.GHOSTS, "ghosts", bool(shown.ghosts)),
            (Action.QUALITY, "high quality", v.multisample),
        )
        for action, text, on in toggles:
            if imgui.checkbox(actions.label(action, text), on)[0]:
                v.perform(action)
            self._remember(f"view {text}")
        changed, shadows = imgui.checkbox("shadows", v.renderer.shadows)
        self._remember("view shadows")
        if changed:
            v.renderer.shadows = shadows
        imgui.separator()
        orbit = v.orbit
        if imgui.radio_button("free-fly (WASD)", not orbit.active) and orbit.active:
            orbit.stop()
        self._remember("camera free")
        imgui.same_line()
        if imgui.radio_button("orbit", orbit.active) and not orbit.active:
            v.view.start_orbit()
        self._remember("camera orbit")
        changed, orbit.follow_wanted = imgui.checkbox("follow the ball orbited", orbit.follow_wanted)
        if changed and not orbit.follow_wanted:
            orbit.follow = None
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(
            MUTED, "orbit: drag turns, scroll zooms, middle button pans; double-click a ball to orbit it"
        )
        imgui.pop_text_wrap_pos()
        self._action_button(Action.HOME, "Scene's view")

    # ------------------------------------------------------------------ Record video
    def _record(self, shown: Shown, watch: Watch) -> None:
        """The MP4 button (F9's action) and the recorder's state: the seconds of video so far, the file
        written, or why it could not record (the run goes on either way)."""
        video = self.viewer.video
        text = "Stop recording" if video.is_recording else "Record MP4"
        self._action_button(Action.RECORD_VIDEO, text, key="Record MP4")
        writer = video.writer  # after the click: it may have started or stopped the recording
        imgui.push_text_wrap_pos(0.0)
        if writer is not None:
            imgui.same_line()
            imgui.push_style_color(imgui.Col_.text, REC)
            imgui.bullet_text(f"REC {writer.duration:.1f} s")  # ImGui's font has no ●: its own bullet
            imgui.pop_style_color()
            self._remember("recording")
            imgui.text_colored(MUTED, f"to {writer.path.name}")
        elif video.error:
            imgui.text_colored(ERROR, video.error)
            self._remember("error video")
        elif video.last_video is not None:
            done = video.last_video
            if done.frames:
                imgui.text(f"saved {done.path.name}: {done.frames} frames, {done.seconds:.2f} s")
            else:
                imgui.text("stopped: no simulated time ran, nothing written")
            self._remember("video saved")
        imgui.text_colored(
            MUTED,
            "Into videos/: the 3-D view and the HUD, not this panel, one frame per 1/30 s of simulated "
            "time (it plays at the run's speed; paused time adds nothing).",
        )
        imgui.pop_text_wrap_pos()
