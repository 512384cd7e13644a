"""Collision: which balls touch or will touch (broad phase, kept pairs, exact geometry, narrow phase,
time of impact). Imports the core and dynamics."""
