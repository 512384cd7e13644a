"""The `ballpit` command line (placeholder until the scene/CLI work lands)."""

from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> int:
    print("ballpit: the viewer and command line are coming; the physics API is ready (import ballpit).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
