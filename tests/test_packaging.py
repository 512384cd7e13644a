"""What ``pip install .`` gets: a wheel with every package under src/ballpit, the shaders and the scenes.

The editable install the Makefile makes finds any subpackage on disk, so a package missing from
pyproject.toml's list goes unnoticed there; a user's ``pip install '.[bench]'`` would then miss it
(``ballpit bench --peers``: "No module named 'ballpit.cli.peers'")."""

from __future__ import annotations

import shutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = {"ballpit.shaders": ROOT / "shaders", "ballpit.scenes": ROOT / "scenes"}


def source_packages() -> list[str]:
    """Every package under src/ballpit, dotted."""
    src = ROOT / "src"
    return sorted(".".join(p.parent.relative_to(src).parts) for p in (src / "ballpit").rglob("__init__.py"))


def test_the_package_list_names_every_package_under_src_and_the_shaders_and_scenes():
    listed = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    assert len(listed) == len(set(listed))
    assert sorted(set(listed) - set(DATA)) == source_packages()
    assert set(DATA) <= set(listed)


@pytest.mark.slow
def test_a_wheel_built_from_the_tree_holds_every_module_shader_and_scene(tmp_path):
    tree = tmp_path / "tree"
    tree.mkdir()
    for name in ("src", "shaders", "scenes"):
        shutil.copytree(ROOT / name, tree / name, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        if (ROOT / name).exists():
            shutil.copy(ROOT / name, tree / name)
    out = tmp_path / "wheel"
    built = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out), str(tree)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert built.returncode == 0, built.stderr
    (wheel,) = out.glob("ballpit-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    expected = {p.relative_to(ROOT / "src").as_posix() for p in (ROOT / "src" / "ballpit").rglob("*.py")}
    for package, folder in DATA.items():
        shipped = [p for p in folder.iterdir() if p.suffix in (".py", ".vert", ".frag", ".glsl", ".toml")]
        expected |= {f"{package.replace('.', '/')}/{p.name}" for p in shipped}
    assert expected - names == set()
