"""The engines the landing grid runs in: each one's settings, its runner and the package it needs."""

from __future__ import annotations

import dataclasses
import importlib.util
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from .ballpit_engine import BallpitRun, BallpitSettings
from .landing import Landing
from .mujoco_engine import MujocoRun, MujocoSettings
from .pybullet_engine import PybulletRun, PybulletSettings


class Run(Protocol):
    """One engine holding one landing grid."""

    engine: str
    version: str
    steps_per_advance: int  # steps of DT that ``advance`` takes

    def advance(self) -> None: ...
    def positions(self) -> np.ndarray: ...
    def velocities(self) -> np.ndarray: ...


KINDS = {bool: "true or false", int: "a whole number", float: "a number", str: "text"}


@dataclass(frozen=True)
class Engine:
    name: str  # as on the command line and in the CSV
    label: str  # as a reader knows it
    package: str | None  # the module it needs beyond ballpit itself
    settings: type
    run: type

    def installed(self) -> bool:
        return self.package is None or importlib.util.find_spec(self.package) is not None

    def configure(self, overrides: dict[str, str]) -> Any:
        """The engine's default settings with ``overrides`` (field name -> text) applied.

        A bad name or value raises ValueError naming it.
        """
        fields = {f.name: f for f in dataclasses.fields(self.settings)}
        changes: dict[str, Any] = {}
        for key, text in overrides.items():
            if key not in fields:
                raise ValueError(f"{self.name} has no setting {key!r} (it has {', '.join(fields)})")
            default = getattr(self.settings(), key)
            try:
                if isinstance(default, bool):
                    if text.lower() not in ("true", "false"):
                        raise ValueError
                    changes[key] = text.lower() == "true"
                else:
                    changes[key] = type(default)(text)
            except ValueError:
                kind = KINDS.get(type(default), type(default).__name__)
                raise ValueError(f"{self.name} setting {key}={text!r}: expected {kind}") from None
        return dataclasses.replace(self.settings(), **changes)

    def start(self, landing: Landing, settings: Any) -> Run:
        return self.run(landing, settings)


ENGINES = {
    e.name: e
    for e in (
        Engine("ballpit", "ballpit", None, BallpitSettings, BallpitRun),
        Engine("mujoco", "MuJoCo", "mujoco", MujocoSettings, MujocoRun),
        Engine("pybullet", "PyBullet", "pybullet", PybulletSettings, PybulletRun),
    )
}
PEERS = ("mujoco", "pybullet")
