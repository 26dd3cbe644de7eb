"""Scenes: one virtual process or test each, with its own deck; ``build`` writes the run folder."""

from .build import Build, build, deck_context, prepare_output

__all__ = ["Build", "build", "deck_context", "prepare_output"]
