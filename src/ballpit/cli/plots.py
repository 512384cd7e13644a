"""Energy plots drawn with matplotlib's Agg canvas (no display needed), written complete or not at all.

``PlotFile`` checks the path and opens a temporary file beside it before the run starts, so a bad
or unwritable path fails at once; the figure is drawn into the temporary file at the end and renamed
into place, so a failed or interrupted run leaves no partial image. matplotlib is an optional
dependency (``pip install 'ballpit[plot]'``): ``PlotFile`` says so up front when it is missing.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from ..physics.dynamics.integrators import INTEGRATORS
from .energy_trace import EnergyRecorder, EnergyTrace
from .writers import AtomicFile, OutputError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

PLOT_FORMATS = (".png", ".svg", ".pdf")
PLOT_DPI = 120
PLOT_SIZE = (8.0, 4.5)  # inches: 960 x 540 pixels at PLOT_DPI
INTEGRATOR_STYLE = {name: {"color": integrator.colour} for name, integrator in INTEGRATORS.items()}
REFERENCE_STYLE = {"color": "0.35", "linestyle": "--"}


MISSING_MATPLOTLIB = "needs matplotlib, which is not installed: pip install 'ballpit[plot]'"


def have_matplotlib() -> bool:
    """Whether matplotlib can be imported (it is the ``plot`` extra, not a core dependency)."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


class PlotFile:
    """A figure file: checked and opened (as a temporary file beside it) now, written on ``commit``."""

    def __init__(self, path: Path, what: str = "--plot") -> None:
        if not have_matplotlib():
            raise OutputError(f"{what} {MISSING_MATPLOTLIB}")
        suffix = path.suffix.lower()
        if suffix not in PLOT_FORMATS:
            raise OutputError(
                f"{path}: {what} must end in {', '.join(PLOT_FORMATS[:-1])} or {PLOT_FORMATS[-1]}, "
                f"not {suffix or 'no suffix'!r}"
            )
        if path.is_dir():
            raise OutputError(f"{path}: {what} is a directory")
        parent = path.parent if str(path.parent) else Path(".")
        if parent.exists() and not parent.is_dir():
            raise OutputError(f"{path}: {what}: {str(parent)!r} is a file, not a directory")
        if not parent.is_dir():
            raise OutputError(f"{path}: {what}: directory {str(parent)!r} does not exist")
        self.path = path
        self.format = suffix.lstrip(".")
        self.out = AtomicFile(path, "wb")  # OutputError now if the folder is not writable

    def commit(self, figure: Figure) -> None:
        """Write ``figure`` and move it into place; on any failure nothing is left behind."""
        try:
            figure.savefig(self.out.file, format=self.format, dpi=PLOT_DPI)
            self.out.commit()
        except OSError as e:
            self.out.discard()
            raise OutputError(f"{self.path}: cannot write: {e.strerror or e}") from None
        except BaseException:
            self.out.discard()
            raise

    def discard(self) -> None:
        self.out.discard()


class EnergyPlot:
    """``simulate --plot``: records the energies every step (pass ``record`` to ``run`` as ``observe``)
    and draws kinetic, potential and total energy over time on ``commit``."""

    def __init__(self, path: Path, title: str) -> None:
        self.file = PlotFile(path)
        self.title = title
        self.record = EnergyRecorder()

    def commit(self) -> None:
        self.file.commit(energy_figure(self.record.trace(), self.title))

    def discard(self) -> None:
        self.file.discard()


def energy_plot(path: Path | None, title: str) -> EnergyPlot | None:
    """An ``EnergyPlot`` writing to ``path`` (checked and opened now), or None without a path."""
    return None if path is None else EnergyPlot(path, title)


def label_log_axis_plainly(axis: object) -> None:
    """Label a log ``axis`` (``ax.xaxis``, ``ax.yaxis``) where matplotlib puts its labels, written
    1.75, 0.5 or 10,000 rather than 1.75×10⁰ (major ticks, and minor ones within a decade or two)."""
    from matplotlib.ticker import LogFormatterSciNotation

    class PlainLog(LogFormatterSciNotation):
        def __call__(self, x: float, pos: int | None = None) -> str:
            return f"{x:,.10g}" if super().__call__(x, pos) else ""

    axis.set_major_formatter(PlainLog())
    axis.set_minor_formatter(PlainLog(labelOnlyBase=False, minor_thresholds=(2, 0.4)))


def _figure() -> Figure:
    """An empty figure on an Agg canvas (no pyplot, no display, no global state)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=PLOT_SIZE, dpi=PLOT_DPI, layout="constrained")
    FigureCanvasAgg(figure)
    return figure


def energy_figure(trace: EnergyTrace, title: str) -> Figure:
    """Kinetic, potential and total energy (J) against time (s)."""
    figure = _figure()
    ax = figure.add_subplot()
    ax.plot(trace.time, trace.kinetic, label="kinetic", color="#d62728", linewidth=1.2)
    ax.plot(trace.time, trace.potential, label="potential", color="#1f77b4", linewidth=1.2)
    ax.plot(trace.time, trace.total, label="total", color="black", linewidth=1.8)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("energy (J)")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
    return figure


def drift_figure(runs: Sequence[tuple[str, EnergyTrace, bool]], title: str) -> Figure:
    """Each run's total-energy drift E(t) − E(0) (J) against time (s).

    ``runs`` holds (label, trace, is_reference); an integrator's label starting with its name picks
    its colour, and the reference is drawn dashed.
    """
    figure = _figure()
    ax = figure.add_subplot()
    for label, trace, reference in runs:
        style = REFERENCE_STYLE if reference else INTEGRATOR_STYLE.get(label.split()[0], {})
        ax.plot(trace.time, trace.drift, label=label, linewidth=1.4, **style)
    ax.axhline(0.0, color="0.6", linewidth=0.8)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("total energy drift E(t) − E(0) (J)")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
    return figure
