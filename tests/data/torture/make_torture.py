"""Rebuild this folder (the sheet-metal torture set's real parts) from the two source repositories.

Run from the repository root, with the source repositories' git directories (bare or not)::

    python tests/data/torture/make_torture.py --laser4diy L4D_GIT_DIR --openamr OPENAMR_GIT_DIR

Every file is read at the pinned commit below with ``git show``.  The Laser4DIY enclosure's STEP assembly
(Fusion 360) is split into single solids with build123d and each part written with OpenCascade without
p-curves (as Fusion 360 writes its STEP files: that keeps the largest part under 1 MB); four variants of the
corner bracket are written with OpenCascade (in inches; every face a B-spline; only the bends B-splines; two
brackets in one file).  The hose adapter, the OpenAMR parts, the Fusion 360 flat patterns (DXF) and the
licences are copied byte for byte.  See PROVENANCE.md and parts.csv.
"""

from __future__ import annotations

import argparse
import subprocess
from pathlib import Path

import build123d as bd
from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_NurbsConvert, BRepBuilderAPI_Sewing
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepTools import BRepTools_ReShape
from OCP.IFSelect import IFSelect_RetDone
from OCP.Interface import Interface_Static
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
from OCP.TopAbs import TopAbs_SHELL
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Compound

HERE = Path(__file__).resolve().parent
L4D_COMMIT = "30f294a4de9d6e0a5b970481bd493e2135daba78"  # Laser4DIY/Laser4DIY_Enclosure, CERN-OHL-P v2
AMR_COMMIT = "3dab2365877f7a671cea38a58f8c352f280ea4bc"  # openAMRobot/OpenAMR, MIT
ASSEMBLY = "CAD/Enclosure v3 v9.step"

# part: (path of the solid in the assembly as build123d reads it, the Fusion 360 body name, its index among the
# assembly's 38 solids in build123d's order)
SPLIT = {
    "l4d_mainsheet": ("MainEnclosure", "MainSheet", 0),
    "l4d_flat_strip": ("MainEnclosure", "BigShim", 1),
    "l4d_compartment_left": ("MainEnclosure", "CompartmentLeftSheet", 2),
    "l4d_compartment_right": ("MainEnclosure", "CompartmentRightSheet", 3),
    "l4d_labyrinth": ("MainEnclosure", "labyrinth", 4),
    "l4d_lid_channel": ("LidChannel", "Body1", 5),
    "l4d_solid_block": ("Deckel/Handle_v7", "Body1", 6),
    "l4d_flat_plate": ("Deckel/COMPOUND", "Body7", 10),
    "l4d_angle": ("Deckel/COMPOUND", "Body4", 11),
    "l4d_corner_bracket": ("CornerBracket", "Body1", 13),
    "l4d_thick_plate": ("LaserChamberv3_v16", "OpticalTable", 22),
    "l4d_chamber_bracket": ("LaserChamberv3_v16", "BracketLeft", 23),
    "l4d_chamber_left": ("LaserChamberv3_v16", "ChamblerLeft", 25),
    "l4d_chamber_top": ("LaserChamberv3_v16", "ChamberTop", 27),
    "l4d_bracket_left": ("COMPOUND", "BracketLeft", 36),
}
MIRRORED_CORNER_BRACKET = 17  # CornerBracket(Mirror): the second bracket of l4d_two_corner_brackets
FLAT = "lasercut/1mm_steel/"
COPIED = {  # file here: (repository, path at its commit)
    "absaug_anschluss.step": ("l4d", "CAD/AbsaugungAnschluss_VersionSchraubanschluss v5.step"),
    "bracket_2pcs.dxf": ("l4d", FLAT + "laserchamberv3_v16/bend_diagrams/bracket_2pcs.dxf"),
    "chamber_sheet_left.dxf": ("l4d", FLAT + "laserchamberv3_v16/bend_diagrams/chamber_sheet_left.dxf"),
    "chamber_sheet_top.dxf": ("l4d", FLAT + "laserchamberv3_v16/bend_diagrams/chamber_sheet_top.dxf"),
    **{f"laserenclosure4_v8_{n}.dxf": ("l4d", FLAT + f"laserenclosure4_v7/bend_diagrams/laserenclosure4_v8_{n}.dxf")
       for n in ("bracketleft", "compartmentright", "cornerbracket_8pcs", "labyrinth", "lidchannel_2pcs")},
    "LICENSE-CERN-OHL-P-2.0.txt": ("l4d", "cern_ohl_p_v2.txt"),
    "LICENSE-OpenAMR-MIT.txt": ("amr", "LICENSE"),
    **{f"amr_{n}.step": ("amr", f"docs/hardware/CAD_files/production_files/{p}.STEP") for n, p in (
        ("drive_shaft", "MMP.03.00.00.004 Drive shaft"), ("pt1_adapter", "PT1.00.00.241 Adapter"),
        ("pt1_bracket", "PT1.00.00.242 Bracket"), ("pt1_camera_body", "PT1.00.00.032 Camera upper body"),
        ("pt1_cover", "PT1.00.00.243 Cover"), ("plastic_cover", "MMP.00.00.00.004 Plastic cover"))},
}


def git_show(git_dir: Path, commit: str, path: str) -> bytes:
    return subprocess.run(["git", "--git-dir", str(git_dir), "show", f"{commit}:{path}"], check=True,
                          capture_output=True).stdout


def write_step(shape, path: Path, unit: str = "MM") -> None:
    """One STEP file, without p-curves (Fusion 360 writes none either), the product named after the file."""
    Interface_Static.SetIVal_s("write.surfacecurve.mode", 0)
    Interface_Static.SetCVal_s("write.step.unit", unit)
    Interface_Static.SetCVal_s("write.step.product.name", path.stem)
    writer = STEPControl_Writer()
    writer.Transfer(shape, STEPControl_AsIs)
    if writer.Write(str(path)) != IFSelect_RetDone:
        raise RuntimeError(f"could not write {path}")
    Interface_Static.SetCVal_s("write.step.unit", "MM")


def only_bends_as_bsplines(solid):
    """The solid with its bend faces rebuilt as B-spline surfaces, the rest unchanged, sewn.

    The bends are the cylindrical faces whose straight edges are longer than the 1 mm sheet is thick (a hole's
    wall has straight edges 1 mm long)."""
    reshape = BRepTools_ReShape()
    for face in bd.Solid(solid).faces():
        if face.geom_type == bd.GeomType.CYLINDER and max(
                (e.length for e in face.edges() if e.geom_type == bd.GeomType.LINE), default=0) > 1.5:
            reshape.Replace(face.wrapped, BRepBuilderAPI_NurbsConvert(face.wrapped, True).Shape())
    sewing = BRepBuilderAPI_Sewing(1e-6)
    sewing.Add(reshape.Apply(solid))
    sewing.Perform()
    shells = TopExp_Explorer(sewing.SewedShape(), TopAbs_SHELL)
    made = BRepBuilderAPI_MakeSolid(TopoDS.Shell(shells.Current()))
    return made.Solid()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--laser4diy", type=Path, required=True, help="git dir of Laser4DIY/Laser4DIY_Enclosure")
    parser.add_argument("--openamr", type=Path, required=True, help="git dir of openAMRobot/OpenAMR")
    parser.add_argument("--out", type=Path, default=HERE)
    args = parser.parse_args(argv)
    sources = {"l4d": (args.laser4diy, L4D_COMMIT), "amr": (args.openamr, AMR_COMMIT)}
    for name, (repo, path) in COPIED.items():
        (args.out / name).write_bytes(git_show(*sources[repo], path))

    assembly = args.out / "_assembly.step"
    assembly.write_bytes(git_show(args.laser4diy, L4D_COMMIT, ASSEMBLY))
    try:
        shape = bd.import_step(assembly)
    finally:
        assembly.unlink()
    solids = []

    def walk(node, path):
        children = list(getattr(node, "children", ()))
        if not children:
            solids.extend((path, s) for s in node.solids())
        for child in children:
            walk(child, f"{path}/{child.label}" if path else child.label)

    walk(shape, "")
    assert len(solids) == 38, len(solids)
    for part, (where, _body, index) in SPLIT.items():
        path, solid = solids[index]
        assert path == where, (part, path, where)
        write_step(solid.wrapped, args.out / f"{part}.step")

    bracket = solids[SPLIT["l4d_corner_bracket"][2]][1].wrapped
    write_step(bracket, args.out / "l4d_corner_bracket_inch.step", unit="INCH")
    write_step(BRepBuilderAPI_NurbsConvert(bracket, True).Shape(), args.out / "l4d_corner_bracket_nurbs.step")
    spline_bend = only_bends_as_bsplines(bracket)
    assert BRepCheck_Analyzer(spline_bend).IsValid()
    write_step(spline_bend, args.out / "l4d_corner_bracket_spline_bend.step")
    two = TopoDS_Compound()
    builder = BRep_Builder()
    builder.MakeCompound(two)
    builder.Add(two, bracket)
    builder.Add(two, solids[MIRRORED_CORNER_BRACKET][1].wrapped)
    write_step(two, args.out / "l4d_two_corner_brackets.step")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
