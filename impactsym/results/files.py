"""File writing for ``impactsym reproduce``: figures (PNG and rasterized PDF) and CSV tables.

Everything goes through the atomic, recorded writer :mod:`impactsym._files`; its names
(:data:`MARKER`, :func:`atomic_path`, :func:`recording`, :func:`write_text`, ...) are
available here too, since ``reproduce`` and its result writers use them together.
"""

from __future__ import annotations

import csv
from pathlib import Path

from impactsym._files import (
    MARKER,
    MARKER_HEADER,
    MARKER_MAX_BYTES,
    PARTIAL,
    PARTIAL_NAME,
    UnsafeTargetError,
    atomic_path,
    check_target,
    describe,
    is_partial,
    read_marker,
    recording,
    write_text,
)

__all__ = [
    "DPI",
    "MARKER",
    "MARKER_HEADER",
    "MARKER_MAX_BYTES",
    "PARTIAL",
    "PARTIAL_NAME",
    "UnsafeTargetError",
    "atomic_path",
    "check_target",
    "describe",
    "is_partial",
    "rasterize_meshes",
    "read_marker",
    "recording",
    "save_figure",
    "write_csv",
    "write_records",
    "write_text",
]


#: Resolution of PNG figures and of the rasterized meshes inside PDF figures.
DPI = 150


def rasterize_meshes(fig) -> None:
    """Mark every mesh of ``fig`` (``pcolormesh``, ``pcolor``, filled contours) rasterized.

    In vector output a mesh is one path per cell (a 400 x 400 map is several MB of PDF);
    rasterized it is one image at :data:`DPI`, while axes, text and lines stay vector.
    """
    from matplotlib import collections
    from matplotlib.contour import ContourSet

    # pcolor's PolyQuadMesh exists from Matplotlib 3.8 on
    meshes = tuple(
        kind
        for kind in (collections.QuadMesh, getattr(collections, "PolyQuadMesh", None))
        if kind is not None
    )
    for ax in fig.axes:
        for artist in ax.collections:
            if isinstance(artist, meshes) or (isinstance(artist, ContourSet) and artist.filled):
                artist.set_rasterized(True)


def save_figure(ax, out: Path, stem: str) -> list[Path]:
    """Save the figure of ``ax`` as PNG and PDF (atomically), close it, return both paths.

    Meshes are rasterized in the PDF (:func:`rasterize_meshes`), which keeps every map
    under 1 MB; a fixed creation date keeps the PDF byte-for-byte reproducible.
    """
    import matplotlib.pyplot as plt

    fig = ax.figure
    try:
        fig.tight_layout()
        rasterize_meshes(fig)
        paths = [out / f"{stem}.png", out / f"{stem}.pdf"]
        for path in paths:
            with atomic_path(path) as tmp:
                fig.savefig(
                    tmp,
                    format=path.suffix[1:],
                    dpi=DPI,
                    metadata={"CreationDate": None} if path.suffix == ".pdf" else None,
                )
    finally:
        plt.close(fig)
    return paths


def write_csv(path: Path, header: list[str], rows) -> Path:
    """Write ``rows`` of numbers under ``header``, each with 17 significant digits."""
    return write_records(path, header, [[f"{v:.17g}" for v in row] for row in rows])


def write_records(path: Path, header: list[str], rows) -> Path:
    """Write ``rows`` (sequences, or dicts keyed by ``header``) as CSV, atomically."""
    path = Path(path)
    with atomic_path(path) as tmp, tmp.open("w", newline="") as handle:
        rows = list(rows)
        if rows and isinstance(rows[0], dict):
            writer = csv.DictWriter(handle, fieldnames=header)
            writer.writeheader()
        else:
            writer = csv.writer(handle)
            writer.writerow(header)
        writer.writerows(rows)
    return path
