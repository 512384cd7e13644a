"""GLSL sources for the viewer, shipped inside the wheel as package data."""
