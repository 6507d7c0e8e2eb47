"""Makes the pictures of docs/python.md from generated meshes (no shared mesh needed):

    python docs/images/make_images.py [OUTPUT_FOLDER]      # default: the folder of this script

Needs exactgeo and matplotlib (pip install .[plot]). python/tests/test_pictures.py runs it into a temporary
folder, so it keeps working.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import exactgeo


def main(folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    mesh = exactgeo.Mesh(*exactgeo.make_bumpy_torus(64, 36))

    # The distance from one vertex, twelve isolines, and the shortest path to the farthest vertex on top.
    d = exactgeo.distance(mesh, 0)
    top = np.flatnonzero(mesh.vertices[:, 2] > 0.2)
    path = exactgeo.path(mesh, 0, int(top[np.argmax(d[top])]))
    exactgeo.plot(mesh, d, path, isolines=12, view=(50, -70), file=folder / "torus-distance.png")

    # Three sources: the distance to the nearest one, with its isolines meeting where the regions meet.
    sources = [0, 800, 1600]
    d = exactgeo.distance(mesh, sources)
    exactgeo.plot(mesh, d, isolines=np.arange(0.15, d.max(), 0.15), view=(50, -70), cmap="plasma",
                  file=folder / "torus-three-sources.png")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent)
