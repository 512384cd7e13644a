"""Bundled scene files (TOML), shipped inside the wheel as package data."""
