"""A World's parameters, each declared once (``World.gravity = Vector(...)``): a descriptor that checks
what is written (TypeError/ValueError naming the parameter and the value) and keeps it in the world's
model under the parameter's own name, where the step reads it."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..core import validation
from .integrators import INTEGRATORS


class Parameter:
    """A World parameter kept in ``world.model`` under its own name, checked on the way in."""

    def __init__(self, doc: str) -> None:
        self.__doc__ = doc

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, world: Any, owner: type | None = None) -> Any:
        if world is None:
            return self
        return self.shown(getattr(world.model, self.name))

    def __set__(self, world: Any, value: object) -> None:
        setattr(world.model, self.name, self.checked(value))

    def shown(self, kept: Any) -> Any:
        """What reading the parameter gives for the value ``kept`` in the model."""
        return kept

    def checked(self, value: object) -> Any:
        """``value`` as the model keeps it, or TypeError/ValueError naming the parameter."""
        return value


class Number(Parameter):
    """A finite number (``validation.number``'s checks), or None where ``optional``."""

    def __init__(self, doc: str, *, optional: bool = False, **checks: bool) -> None:
        super().__init__(doc)
        self.optional, self.checks = optional, checks

    def checked(self, value: object) -> float | None:
        if value is None and self.optional:
            return None
        return validation.number(self.name, value, **self.checks)


class Count(Parameter):
    """A whole number of at least 1 (and at most ``most``)."""

    def __init__(self, doc: str, most: int | None = None) -> None:
        super().__init__(doc)
        self.most = most

    def checked(self, value: object) -> int:
        return validation.whole_number(self.name, value, 1, self.most)


class Flag(Parameter):
    """True or false."""

    def checked(self, value: object) -> bool:
        if not isinstance(value, bool | np.bool_):
            raise TypeError(f"{self.name} must be true or false, got {value!r}")
        return bool(value)


class Vector(Parameter):
    """Three finite numbers, each at most ``limit`` in size; read as a read-only array (assign a whole
    vector to change it)."""

    def __init__(self, doc: str, limit: float = math.inf) -> None:
        super().__init__(doc)
        self.limit = limit

    def shown(self, kept: np.ndarray) -> np.ndarray:
        view = kept.view()
        view.flags.writeable = False
        return view

    def checked(self, value: object) -> np.ndarray:
        return validation.vector(self.name, value, limit=self.limit)


class Integrator(Parameter):
    """One of the registered integrators (integrators.py), by name; read as its name."""

    def shown(self, kept: Any) -> str:
        return kept.name

    def checked(self, value: object) -> Any:
        if not isinstance(value, str) or value.lower() not in INTEGRATORS:
            raise ValueError(f"{self.name} must be one of {', '.join(INTEGRATORS)}, got {value!r}")
        return INTEGRATORS[value.lower()]
