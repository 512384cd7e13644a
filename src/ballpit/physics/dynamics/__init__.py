"""Dynamics: how balls move when nothing touches them (the model, forces, integrators, moving planes)
and when they may stop (sleeping). Imports only the core."""
