"""Loading scene files: ``read_scene`` (the World with its appearance, timestep and duration), the
``load_scene`` shorthand for the World alone, and where the bundled scenes are."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from ..physics import World
from .appearance import Scene
from .builder import Builder
from .reading import read_toml


def read_scene(path: str | Path) -> Scene:
    """Read and validate a scene file; return its Scene (``.world``, ``.appearance``, ``.timestep``,
    ``.duration``).

    Raises ``SceneError`` (a ``ValueError``) for a missing file, bad TOML or any bad value.
    """
    path = Path(path)
    text, data = read_toml(path)
    return Builder(path, text, data).build()


def load_scene(path: str | Path) -> World:
    """Read and validate a scene file; return its World (``read_scene`` gives the rest of the scene)."""
    return read_scene(path).world


def bundled_scenes_dir() -> Path:
    """The directory of the scenes shipped with ballpit (``ballpit.scenes`` when installed)."""
    try:
        found = Path(str(resources.files("ballpit.scenes")))
        if found.is_dir():
            return found
    except (ModuleNotFoundError, TypeError):
        pass
    return Path(__file__).resolve().parents[3] / "scenes"  # a source checkout


def bundled_scenes() -> list[Path]:
    """Every bundled scene file, sorted by name."""
    return sorted(bundled_scenes_dir().glob("*.toml"))


def default_scene_path() -> Path:
    """The default demo, ``slopes.toml``."""
    return bundled_scenes_dir() / "slopes.toml"


def unknown_scene(name: str) -> str | None:
    """For a bare name that is neither a file nor a bundled scene ("slope"): one line naming the close
    bundled names and listing them all; None for anything else (a path to a missing file says so)."""
    path = Path(name)
    stem = path.name.removesuffix(".toml")
    if path.parent != Path(".") or not stem or resolve_scene_path(name).exists():
        return None
    import difflib

    names = [p.stem for p in bundled_scenes()]
    close = difflib.get_close_matches(stem, names, n=3, cutoff=0.5)
    hint = f"did you mean {' or '.join(close)}? " if close else ""
    return f"no scene file or bundled scene named {name!r}: {hint}bundled scenes: {', '.join(names)}"


def resolve_scene_path(name: str | Path) -> Path:
    """A scene argument as a path: an existing file, else a bundled scene's name (``slopes``).

    An unknown name comes back unchanged, so loading it reports the missing file.
    """
    path = Path(name)
    try:
        if path.exists():
            return path
    except OSError:  # e.g. a name too long for the file system: reading it will say so
        return path
    stem = path.name.removesuffix(".toml")
    if path.parent == Path(".") and stem:
        bundled = bundled_scenes_dir() / f"{stem}.toml"
        if bundled.is_file():
            return bundled
    return path
