"""Write the bundled CAD samples' STEP files (run from the repository root).

    python samples/make_cad.py

The parts are built by :mod:`patterns.samples` (see there what each one is);
the STEP files are committed, and this script is how they were made.
"""

from __future__ import annotations

from pathlib import Path

from build123d import export_step

from patterns.samples import SAMPLES

HERE = Path(__file__).resolve().parent


def main() -> None:
    for name, make in SAMPLES.items():
        shape = make()
        export_step(shape, HERE / name)
        print(f"wrote samples/{name}: {len(shape.faces())} faces, {len(shape.edges())} edges, "
              f"area {shape.area:.1f} mm^2")


if __name__ == "__main__":
    main()
