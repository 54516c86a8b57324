"""Sheet metal: unfold a bent part into one flat blank, as SolidWorks and FreeCAD's SheetMetal do.

An unfold is a pipeline of stages over frozen records, like the CAD mesher:

1. :func:`~patterns.sheetmetal.faces.recognise` -- every face with the
   surface the mesher's recogniser finds (plane, cylinder, cone, or none);
2. :func:`~patterns.sheetmetal.sheet.find_sheet` -- the fixed face, the
   thickness and the skin (a :class:`~patterns.sheetmetal.sheet.SheetModel`);
3. :mod:`~patterns.sheetmetal.bends` -- each bend face's curvature, the bends
   (:class:`~patterns.sheetmetal.bends.BendGroup`, developed to their neutral
   width: ``angle (r + K t)`` or a bend table's), and every skin face's exact
   map to the flat (:class:`~patterns.sheetmetal.bends.FaceMap`); a face that
   is none of these is meshed and flattened
   (:mod:`~patterns.sheetmetal.meshed`), with its strain reported;
4. :func:`~patterns.sheetmetal.join.place_faces` -- the faces joined by rigid
   motions from the fixed face outwards, every shared edge checked to meet;
5. :mod:`~patterns.sheetmetal.contour` -- the cut contour as exact lines and
   arcs, chained into loops, the bend lines, and flanges that collide.

The result is a :class:`patterns.Blank`, whose findings are the same
:class:`patterns.Finding` records :func:`patterns.check` reports.
"""

from __future__ import annotations

from dataclasses import replace
from functools import partial
from pathlib import Path

import numpy as np

from ..blank import Bend, Blank
from ..errors import InputError
from ..findings import Code, Finding, Severity
from ..reading import CAD_SUFFIXES, check_source, read_cad
from ..tessellate.topology import read_topology
from ..text import counted
from .bends import curvatures, face_maps, group_bends
from .contour import bend_line, clip_to, contour_faults, cut_loops, overlaps
from .faces import recognise, uv_mid
from .holes import hole_rims
from .imported import prepared
from .join import flat, place_faces
from .meshed import meshed_face
from .oblique import neutral_trace
from .rules import manufacturability, open_contours
from .sheet import check_volume, find_sheet
from .table import BendTable, UnfoldOptions, read_bend_table

__all__ = ["BendTable", "UnfoldOptions", "read_bend_table", "unfold"]


def _shape(source, name):
    from OCP.TopoDS import TopoDS_Shape

    if isinstance(source, (str, Path)):
        return read_cad(check_source(source, CAD_SUFFIXES)), name or Path(source).stem
    wrapped = getattr(source, "wrapped", source)  # a build123d shape wraps its OCP one
    if not isinstance(wrapped, TopoDS_Shape):
        raise InputError(f"unfold takes a STEP/BREP/IGES path or a build123d/OCP shape, got {type(source).__name__}")
    return wrapped, name or "part"


def unfold(shape_or_path, options: UnfoldOptions | None = None, *, name: str | None = None, **keywords) -> Blank:
    """Unfold a bent sheet-metal part into its flat blank.

    Parameters
    ----------
    shape_or_path : str, Path, build123d shape or OCP ``TopoDS_Shape``
        The folded solid (STEP, BREP or IGES file, mm).
    options : UnfoldOptions, optional
        The options as a record; keywords (``k_factor``, default 0.5;
        ``bend_table``, a CSV path or :class:`BendTable`; ``material``, its K-factors from a material table;
        ``fixed_face``) go over it.
    name : str, optional
        For messages and the report (default: the file's stem).

    Returns
    -------
    patterns.Blank
        The outline and holes (exact lines and arcs), the bend lines, the
        thickness read from the model, and findings (flanges that overlap once
        unfolded, a bend with no flat face on one side, a meshed face).  The
        fixed face keeps its own plane coordinates.

    Raises
    ------
    InputError
        Not a sheet of constant thickness, a closed tube, a bad option, a bend the table does not cover.
    CadError
        The file cannot be read.
    """
    shape, name = _shape(shape_or_path, name)
    opts = UnfoldOptions.of(options, keywords, name=name)
    shape = prepared(shape, name)  # one solid; B-spline faces that are planes, cylinders or cones made so
    topology = read_topology(shape, name=name)
    faces = recognise(topology)
    sheet = find_sheet(shape, topology, faces, opts.fixed_face, name)
    curvature = curvatures(faces, sheet, name)
    meshed = {i: meshed_face(faces[i], sheet.thickness, opts.k_factor if opts.material is None else  # K even with a
                           partial(opts.k_factor_at, sheet.thickness, what=f"{name}: face {i}"), name)  # bend table
              for i in sorted(sheet.skin) if faces[i].kind == "other"}
    check_volume(shape, sheet, faces, {i: (c.bend_radius, c.inside_radius) for i, c in curvature.items()}, meshed,
                 name)
    bends = group_bends(faces, sheet, curvature, opts, name)
    maps = face_maps(faces, sheet, curvature, bends, meshed, opts.k_factor)
    motions, gaps = place_faces(topology, maps, sheet, name)
    lines = [bend_line(maps, motions, b) for b in bends]
    zones = {i: (line, b.allowance / 2) for b, line in zip(bends, lines) for i in b.faces}
    missed: list = []  # corners a relief of the size asked does not reach
    relief_size = opts.relief_size(sheet.thickness)
    chains: list = []  # each loop's skin edges
    loops, open_ends = cut_loops(topology, maps, motions, sheet.skin, name, relief=opts.corner_relief,
                                 thickness=sheet.thickness, bend_lines=zones, relief_size=relief_size,
                                 missed=missed, chains=chains)
    outline = max(loops, key=lambda lp: lp[0].area)[0]
    oblique = []  # holes across a bend with a wall not square to the sheet: drawn on the neutral layer
    for k, ((loop, _), chain) in enumerate(zip(loops, chains)):
        retraced = None if loop is outline or chain is None else neutral_trace(
            chain, topology=topology, faces=faces, sheet=sheet, bends=bends, maps=maps, motions=motions)
        if retraced is not None:
            oblique.append((loop, retraced, sorted({e for e, _, _ in chain})))
            if retraced.loop is not None:
                loops[k] = (retraced.loop, retraced.faces)
    holes = tuple(lp for lp, _ in loops if lp is not outline)
    holes, rims = hole_rims(topology, faces, maps, motions, sheet, holes)  # countersinks: cut at the through hole
    lines = [clip_to(line, outline) for line in lines]  # a bend line ends where a corner relief cuts its zone
    ks = {b.k_factor for b in bends}  # a material's: the one K-factor of every bend, or None
    k_factor = None if opts.bend_table is not None else opts.k_factor if opts.material is None else \
        (ks.pop() if len(ks) == 1 else None)
    drawn = tuple(Bend(line=line, angle=b.angle, inside_radius=b.inside_radius,
                       direction=b.direction, allowance=b.allowance, faces=b.faces, k_factor=b.k_factor)
                  for b, line in zip(bends, lines))
    findings = list(overlaps(topology, maps, motions, sheet.skin, gaps, name))
    findings += open_contours(open_ends, name)
    findings += contour_faults(loops, sheet.thickness, name, overlapping=bool(findings))
    findings += [Finding(Code.BEND_WITHOUT_FLANGE, Severity.NOTE, (name,), bend.line.mean(axis=0)[None, :], (), None,
                         f"{name}: bend at faces {', '.join(map(str, bend.faces))} has no flat face on one side")
                 for bend, group in zip(drawn, bends) if not group.flanged]
    findings += [Finding(
        Code.OBLIQUE_CUT, Severity.NOTE, (name,), (retraced.loop or skin).vertices()[:, :2].mean(axis=0)[None, :], (),
        None, f"{name}: the cut at edges {', '.join(map(str, edges))} crosses a bend with its wall not square to the "
        f"sheet (drilled after bending): " + (
            f"drawn as the wall's trace on the neutral layer, {retraced.loop.area:.2f} mm² (the fixed face's trace "
            f"{skin.area:.2f} mm²)" if retraced.loop is not None else
            f"drawn as the fixed face's trace, {skin.area:.2f} mm², not on the neutral layer: {retraced.why}; the "
            f"hole cut in the blank and bent will not be the model's"))
        for skin, retraced, edges in oblique]
    if missed:
        findings.append(Finding(
            Code.RELIEF_NOT_DRAWN, Severity.NOTE, (name,), np.array(missed), (), None,
            f"{name}: {counted(len(missed), 'corner')} drawn closed: a {opts.corner_relief} relief "
            f"{relief_size:g} mm across does not reach the flanges' edges there (they are "
            f"further from the bend lines' crossing); give a larger size, or leave it out for the one that "
            f"clears both bend zones"))
    for i, m in sorted(meshed.items()):
        d = m.flattening.distortion
        findings.append(Finding(
            Code.MESHED_FACE, Severity.NOTE, (name,), flat(maps, motions, i, [uv_mid(faces[i].face)]), (), None,
            f"{name}: face {i} is not developable as a plane, cylinder or cone: meshed "
            f"({counted(len(m.triangles), 'triangle')}) and flattened, strain up to {d.strain_max:.3%} (rms "
            f"{d.strain_rms:.3%}); its edges land within {gaps[i]:.3f} mm of the faces beside it"))
    order = {Severity.ERROR: 0, Severity.LIMIT: 1, Severity.NOTE: 2}
    findings.sort(key=lambda f: order[f.severity])
    blank = Blank(name=name, outline=outline, holes=holes, bends=drawn, thickness=sheet.thickness,
                  k_factor=k_factor, fixed_face=sheet.fixed, findings=tuple(findings), material=opts.material,
                  rims=rims)
    return replace(blank, findings=blank.findings + manufacturability(blank))  # a shop's notes, after the rest
