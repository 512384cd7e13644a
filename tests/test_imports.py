"""The layers of src/ import downwards only: no module imports one that imports it back, directly or
through others (an ``ast`` reading of every import, at module level or inside a function, as Python
would resolve it; in the physics those made for type hints alone count too), and the physics imports
neither the viewer, the scenes nor the command line, nor pyglet or OpenGL."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"


def module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _nodes(tree: ast.AST, hints: bool):
    """Every node of ``tree``, leaving out the blocks under ``if TYPE_CHECKING:`` unless ``hints``."""
    for node in ast.iter_child_nodes(tree):
        if not hints and isinstance(node, ast.If) and getattr(node.test, "id", None) == "TYPE_CHECKING":
            continue
        yield node
        yield from _nodes(node, hints)


def imports(path: Path, modules: set[str], hints: bool = False) -> set[str]:
    """The modules of ``modules`` that the file at ``path`` imports (``from . import x`` names module x
    when there is one; ``from .m import name`` names module m). A module's own packages are left out:
    Python imports them before it, whatever it says."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in _nodes(ast.parse(path.read_text(), str(path)), hints):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                source = ".".join([*base, node.module] if node.module else base)
            else:
                source = node.module or ""
            found.add(source)
            found.update(f"{source}.{alias.name}" for alias in node.names)
    parents = {".".join(name.split(".")[:k]) for k in range(1, name.count(".") + 1)}
    return {m for m in found if m in modules and m != name and m not in parents}


def graph(under: str = "ballpit", hints: bool = False) -> dict[str, set[str]]:
    """Each module of ``under`` and the modules of it that it imports (type hints' too if ``hints``)."""
    files = sorted(SRC.rglob("*.py"))
    modules = {module_name(p) for p in files if module_name(p).startswith(under)}
    return {m: imports(p, modules, hints) for p in files if (m := module_name(p)) in modules}


def cycle(edges: dict[str, set[str]]) -> list[str] | None:
    """One import cycle, as the modules along it, or None (a depth-first search)."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(m: str) -> list[str] | None:
        state[m] = 1
        path.append(m)
        for n in sorted(edges[m]):
            if state.get(n) == 1:
                return [*path[path.index(n) :], n]
            if n not in state and (found := visit(n)) is not None:
                return found
        path.pop()
        state[m] = 2
        return None

    for m in sorted(edges):
        if m not in state and (found := visit(m)) is not None:
            return found
    return None


def test_the_reader_finds_a_cycle_it_is_shown():
    assert cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert cycle({"a": {"b"}, "b": set()}) is None


def test_no_module_in_src_imports_itself_back():
    edges = graph()
    assert len(edges) > 50 and "ballpit.physics.world" in edges["ballpit.physics"]
    found = cycle(edges)
    assert found is None, " -> ".join(found)


def test_no_physics_module_imports_itself_back_even_for_type_hints():
    found = cycle(graph("ballpit.physics", hints=True))
    assert found is None, " -> ".join(found)


def test_the_physics_imports_no_layer_above_it_and_no_window():
    for name, targets in graph().items():
        if name.startswith("ballpit.physics"):
            above = {t for t in targets if t.startswith(("ballpit.viewer", "ballpit.scene", "ballpit.cli"))}
            assert not above, (name, above)
    for path in (SRC / "ballpit" / "physics").rglob("*.py"):
        tree = ast.parse(path.read_text())
        names = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        names |= {n.module or "" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
        assert not {m for m in names if m.split(".")[0] in ("pyglet", "OpenGL")}, path


ROOMS = ("core", "dynamics", "collision", "contact", "step")  # each imports only those before it


def room(module: str) -> int | None:
    """Where ``module`` sits in ROOMS (None for the physics' root modules: the facade over them all)."""
    parts = module.split(".")
    return ROOMS.index(parts[2]) if len(parts) > 2 and parts[2] in ROOMS else None


def test_each_physics_room_imports_only_the_rooms_below_it():
    rooms = {p.name for p in (SRC / "ballpit" / "physics").iterdir() if (p / "__init__.py").exists()}
    assert rooms == set(ROOMS)
    for name, targets in graph("ballpit.physics", hints=True).items():
        if (here := room(name)) is None:
            continue
        above = {t for t in targets if room(t) is None or room(t) > here}
        assert not above, (name, above)
