"""``python -m impactsym`` runs the command-line interface."""

from impactsym.cli import run

run()
