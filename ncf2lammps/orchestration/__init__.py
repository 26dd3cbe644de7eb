"""Orchestration above the scenes: build a run folder, run its scenes in order, study a grid of
knobs, export an HPC bundle, report a folder (figures and summary.md)."""
