"""Write the bundled sample meshes (run from the repository root).

    python samples/make_meshes.py

Each sample is a generated surface of :mod:`patterns.surfaces`, in millimetres,
written as OBJ with its vertices in the generator's order.
"""

from pathlib import Path

import trimesh

from patterns import surfaces

HERE = Path(__file__).resolve().parent

SAMPLES = {
    # A shallow paraboloid dish, 600 mm across, 54 mm deep: doubly curved.
    "dish.obj": surfaces.paraboloid_dish(diameter=600.0, sag=54.0, n_faces=2_000),
    # Half a cone frustum triangulated along its rulings: exactly developable.
    "cone.obj": surfaces.cone_patch(r_bottom=250.0, r_top=100.0, height=300.0, angle=180.0,
                                    n_around=36, n_along=12),
}


def main() -> None:
    for name, (vertices, faces) in SAMPLES.items():
        mesh = trimesh.Trimesh(vertices, faces, process=False)
        mesh.export(HERE / name)
        print(f"wrote samples/{name}: {len(vertices)} vertices, {len(faces)} faces")


if __name__ == "__main__":
    main()
