"""File writing shared by the ``impactsym reproduce`` writers (deterministic output)."""

from __future__ import annotations

import csv
from pathlib import Path


def save_figure(ax, out: Path, stem: str) -> list[Path]:
    """Save the figure of ``ax`` as PNG and PDF, close it, return both paths."""
    import matplotlib.pyplot as plt

    fig = ax.figure
    fig.tight_layout()
    paths = [out / f"{stem}.png", out / f"{stem}.pdf"]
    for path in paths:
        # a fixed creation date keeps the PDF byte-for-byte reproducible
        fig.savefig(
            path, dpi=150, metadata={"CreationDate": None} if path.suffix == ".pdf" else None
        )
    plt.close(fig)
    return paths


def write_csv(path: Path, header: list[str], rows) -> Path:
    """Write ``rows`` of numbers under ``header``, each with 17 significant digits."""
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(header)
        writer.writerows([[f"{v:.17g}" for v in row] for row in rows])
    return path
