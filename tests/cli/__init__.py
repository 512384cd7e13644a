"""Tests of the command line and the headless tools (src/ballpit/cli/)."""
