"""Saving the report's figures: files beside the HTML and the same bytes embedded in it.

Every figure is written as PNG (and the matplotlib ones also as SVG and PDF);
`Figure` records the files and carries the PNG as a ``data:`` URI, so
``report.html`` shows every image without the files beside it.
"""

from __future__ import annotations

import base64
from dataclasses import dataclass
from pathlib import Path

#: Metadata that would make the SVG and PDF files differ from run to run.
_NO_DATES = {"svg": {"Date": None}, "pdf": {"CreationDate": None, "ModDate": None}}


@dataclass(frozen=True)
class Figure:
    """One figure of the report.

    ``files``: the names written beside the HTML, PNG first; ``alt``: a plain
    text description for the image's alt attribute; ``data_uri``: the PNG,
    base64-encoded, as the ``src`` of the embedded image.
    """

    key: str
    files: tuple[str, ...]
    alt: str
    data_uri: str

    @property
    def png(self) -> str:
        return self.files[0]

    @property
    def extra(self) -> tuple[str, ...]:
        """The files other than the PNG (SVG, PDF)."""
        return self.files[1:]


def png_data_uri(path: Path) -> str:
    """``data:image/png;base64,…`` of the PNG file ``path``."""
    return "data:image/png;base64," + base64.b64encode(Path(path).read_bytes()).decode("ascii")


def save_formats(fig, folder: Path, stem: str, exts: tuple[str, ...]) -> list[str]:
    """Save ``fig`` as ``stem.<ext>`` in ``folder`` for each of ``exts``, in order; the names.

    The first save lays the figure out (its layout engine: constrained layout); the engine
    is then removed (``fig.set_layout_engine(None)``: the axes keep the positions it gave
    them), so the other formats draw the same layout without computing it again, and
    without the layout pass matplotlib makes before every save of a figure that has an
    engine, even a placeholder one (``"none"``): a report's SVG and PDF saves took half as
    long again with it, and the layout was a third of the drawing time of its figures.
    """
    names = []
    for k, ext in enumerate(exts):
        fig.savefig(folder / f"{stem}.{ext}", metadata=_NO_DATES.get(ext))
        names.append(f"{stem}.{ext}")
        if k == 0 and fig.get_layout_engine() is not None:
            fig.set_layout_engine(None)
            if fig.get_layout_engine() is not None:  # rc asks for a default engine: a placeholder
                fig.set_layout_engine("none")
    return names


def save_matplotlib(fig, folder: Path, stem: str, key: str, alt: str) -> Figure:
    """Save a matplotlib figure as ``stem``.png/.svg/.pdf in ``folder``, close it, return the record."""
    import matplotlib.pyplot as plt

    try:
        names = save_formats(fig, folder, stem, ("png", "svg", "pdf"))
    finally:
        plt.close(fig)
    return Figure(key, tuple(names), alt, png_data_uri(folder / names[0]))


def save_plotter(plotter, folder: Path, stem: str, key: str, alt: str) -> Figure:
    """Screenshot an off-screen pyvista plotter to ``stem``.png, close it, return the record."""
    try:
        plotter.screenshot(str(folder / f"{stem}.png"))
    finally:
        plotter.close()
    return Figure(key, (f"{stem}.png",), alt, png_data_uri(folder / f"{stem}.png"))
