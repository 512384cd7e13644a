"""``ballpit bench --peers``: the landing grid in every engine, round after round; the medians, the
ratios to the best peer, each engine's overlap and stillness, a CSV of every run and a plot."""

from __future__ import annotations

import csv
import os
import platform
import statistics
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..arguments import one_line
from ..writers import AtomicFile, OutputError, check_name_lengths
from .engines import ENGINES, PEERS
from .landing import DT, FRICTION, RESTITUTION
from .measure import DROP_SPEED, Landed
from .rounds import installed_peers, interleaved, land_isolated

CSV_COLUMNS = (
    "engine",
    "version",
    "settings",
    "balls",
    "round",
    "steps",
    "seconds",
    "steps_per_second",
    "max_overlap_r",
    "final_max_speed",
    "inside",
    "bounce_e",
    "load",
)


@dataclass
class Row:
    """One run as the CSV holds it: the landing and the round it ran in, with the load after it."""

    landed: Landed
    round: int
    load: float

    def values(self) -> tuple:
        r = self.landed
        return (
            r.engine,
            r.version,
            r.settings,
            r.n,
            self.round,
            r.steps,
            f"{r.seconds:.6g}",
            f"{r.steps_per_second:.6g}",
            f"{r.max_overlap:.6g}",
            f"{r.final_speed:.6g}",
            r.inside,
            f"{r.bounce:.4g}",
            f"{self.load:.2f}",
        )


@dataclass
class Summary:
    """One engine at one size over every round: the median rate and the worst of each measure."""

    engine: str
    n: int
    rates: list[float]
    max_overlap: float
    final_speed: float
    inside: int
    bounce: float

    @property
    def median(self) -> float:
        return statistics.median(self.rates)


def summarise(rows: list[Row]) -> list[Summary]:
    """Each (engine, size) seen in ``rows``, in the order first seen."""
    groups: dict[tuple[str, int], list[Landed]] = {}
    for row in rows:
        groups.setdefault((row.landed.engine, row.landed.n), []).append(row.landed)
    return [
        Summary(
            engine,
            n,
            [r.steps_per_second for r in runs],
            max(r.max_overlap for r in runs),
            max(r.final_speed for r in runs),
            min(r.inside for r in runs),
            statistics.median(r.bounce for r in runs),
        )
        for (engine, n), runs in groups.items()
    ]


def best_peer(summaries: list[Summary], n: int) -> Summary | None:
    """The fastest peer (by median) at ``n`` balls, if any peer ran."""
    peers = [s for s in summaries if s.n == n and s.engine in PEERS]
    return max(peers, key=lambda s: s.median, default=None)


def table(summaries: list[Summary]) -> list[str]:
    """The summary: one line per engine and size, with its ratio to the best peer at that size."""
    lines = [
        f"{'balls':>6}  {'engine':9} {'steps/s':>9} {'(min-max)':>19} {'vs best peer':>12} "
        f"{'max overlap':>11} {'max speed at end':>16} {'inside':>11} {'bounce e':>8}"
    ]
    for s in summaries:
        best = best_peer(summaries, s.n)
        ratio = f"{s.median / best.median:.2f}x" if best is not None else ""
        spread = f"({min(s.rates):.1f}-{max(s.rates):.1f})"
        lines.append(
            f"{s.n:6d}  {s.engine:9} {s.median:9.1f} {spread:>19} {ratio:>12} {s.max_overlap:9.3f} r "
            f"{s.final_speed:12.4f} m/s {f'{s.inside}/{s.n}':>11} {s.bounce:8.3f}"
        )
    return lines


def check_csv_path(path: Path) -> None:
    """OutputError unless ``path`` can be a CSV file (its suffix, its folder)."""
    if path.suffix.lower() != ".csv":
        raise OutputError(f"{path}: --csv must end in .csv, not {path.suffix or 'no suffix'!r}")
    check_name_lengths(path, "--csv")
    if path.is_dir():
        raise OutputError(f"{path}: --csv is a directory")


def figure(summaries: list[Summary]) -> object:
    """Two panels against the number of balls: steps/s (log-log; bars span the rounds) and max overlap."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import NullLocator

    from ..plots import label_log_axis_plainly

    fig = Figure(figsize=(10.0, 4.2), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    rate, overlap = fig.subplots(1, 2)
    for engine in dict.fromkeys(s.engine for s in summaries):
        runs = sorted((s for s in summaries if s.engine == engine), key=lambda s: s.n)
        ns = [s.n for s in runs]
        medians = [s.median for s in runs]
        spread = [
            [m - min(s.rates) for m, s in zip(medians, runs, strict=True)],
            [max(s.rates) - m for m, s in zip(medians, runs, strict=True)],
        ]
        label = ENGINES[engine].label
        rate.errorbar(ns, medians, yerr=spread, marker="o", capsize=3, label=label)
        overlap.plot(ns, [s.max_overlap for s in runs], marker="o", label=label)
    sizes = sorted({s.n for s in summaries})
    for ax in (rate, overlap):
        ax.set_xscale("log")
        ax.set_xticks(sizes, labels=[f"{n:,}" for n in sizes])
        ax.xaxis.set_minor_locator(NullLocator())
    rate.set_yscale("log")
    label_log_axis_plainly(rate.yaxis)
    rate.set_xlabel("balls")
    rate.set_ylabel("steps of 1/240 s per second (median)")
    rate.set_title("the landing grid: step rate")
    overlap.set_xlabel("balls")
    overlap.set_ylabel("deepest overlap (fraction of the radius)")
    overlap.set_ylim(bottom=0)
    overlap.set_title("deepest overlap while landing")
    for ax in (rate, overlap):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    return fig


def run_peers(
    sizes: list[int],
    steps: int,
    rounds: int,
    timeout: float,
    csv_path: Path | None = None,
    plot_path: Path | None = None,
    engines: list[str] | None = None,
    land_one: Callable[..., Landed | str] = land_isolated,
) -> int:
    """Run the comparison, print it, write the CSV and the plot; the exit status (2: bad output path
    or no peer installed; 1: some run failed)."""
    from ..plots import PlotFile

    engines = engines or ["ballpit", *PEERS]
    engines, missing = installed_peers(engines)
    for engine in missing:
        print(
            f"ballpit bench: {ENGINES[engine].label} is not installed, so it is left out "
            "(pip install 'ballpit[bench]')",
            file=sys.stderr,
        )
    if not any(e in PEERS for e in engines):
        print(
            "ballpit bench: --peers needs MuJoCo or PyBullet: pip install 'ballpit[bench]'", file=sys.stderr
        )
        return 2
    outputs = []
    try:
        if csv_path is not None:
            check_csv_path(csv_path)
            outputs.append(AtomicFile(csv_path))
        if plot_path is not None:
            outputs.append(PlotFile(plot_path))
    except OutputError as e:
        for out in outputs:
            out.discard()
        print(f"ballpit bench: {one_line(str(e))}", file=sys.stderr)
        return 2
    try:
        status = _run(engines, sizes, steps, rounds, timeout, outputs, csv_path, land_one)
    except BaseException:
        for out in outputs:
            out.discard()
        raise
    return status


def _run(engines, sizes, steps, rounds, timeout, outputs, csv_path, land_one) -> int:
    machine = platform.processor() or platform.machine()
    print(
        f"ballpit bench --peers: the landing grid (balls 0.11 m apart falling into a box), its first "
        f"{steps * DT:g} s ({steps} steps of 1/{round(1 / DT)} s); every contact e = {RESTITUTION:g}, "
        f"mu = {FRICTION:g}; {rounds} round(s), the engines taking turns, each run in its own process"
    )
    print(
        f"machine: {machine}, {os.cpu_count()} cores, Python {platform.python_version()}, "
        f"load {_load():.2f} at the start"
    )
    rows: list[Row] = []
    failed = 0
    for r, result, engine, n in interleaved(engines, sizes, steps, rounds, timeout, land_one):
        if isinstance(result, str):
            failed += 1
            print(
                f"ballpit bench: {ENGINES[engine].label} N={n} round {r}: failed: {result}", file=sys.stderr
            )
            continue
        rows.append(Row(result, r, _load()))
        print(
            f"  round {r}  {engine:9} N={n:<6d} {result.steps_per_second:9.1f} steps/s  "
            f"overlap {result.max_overlap:.3f} r  max speed at end {result.final_speed:.4f} m/s",
            flush=True,
        )
    print(f"load {_load():.2f} at the end")
    summaries = summarise(rows)
    print("\n".join(table(summaries)))
    print(
        f"(steps/s: median over the rounds; vs best peer: over the faster of the peers at that size; "
        f"max overlap: the deepest of any ball into another, the floor or a wall, sampled every "
        f"1/60 s; inside: balls left in the box; bounce e: a ball dropped onto the floor at "
        f"{DROP_SPEED:g} m/s, sqrt of rebound over drop height)"
    )
    print("settings:")
    for engine in dict.fromkeys(row.landed.engine for row in rows):
        first = next(row.landed for row in rows if row.landed.engine == engine)
        print(f"  {ENGINES[engine].label} {first.version}: {first.settings}")
    for out in outputs:
        if isinstance(out, AtomicFile):
            writer = csv.writer(out.file, lineterminator="\n")
            writer.writerow(CSV_COLUMNS)
            writer.writerows(row.values() for row in rows)
            out.commit()
            print(f"wrote {csv_path} ({len(rows)} runs)")
        elif summaries:
            out.commit(figure(summaries))
            print(f"wrote {out.path}")
        else:
            out.discard()
    if failed:
        print(f"ballpit bench: {failed} of {failed + len(rows)} runs failed", file=sys.stderr)
        return 1
    return 0


def _load() -> float:
    try:
        return os.getloadavg()[0]
    except OSError:
        return float("nan")
