"""Helpers shared by the tests (independent of the code under test)."""

import subprocess
from pathlib import Path

import numpy as np
import pytest
import shapely


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random proper rotation (3, 3)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    return q


def rigid_fit_residual(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance left after the best 2D rigid motion (no scaling) of ``a`` onto ``b``.

    Independent of the code under test: Kabsch/Procrustes by SVD.
    """
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    h = (a - ca).T @ (b - cb)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(vt.T @ u.T))
    rot = vt.T @ np.diag([1.0, d]) @ u.T
    return float(np.abs((a - ca) @ rot.T - (b - cb)).max())


def independent_one_to_one(faces: np.ndarray, uv: np.ndarray) -> bool:
    """One-to-one by area, with shapely only: every triangle counter-clockwise and
    the union of all triangles as large as the sum of their areas."""
    tris = shapely.polygons(uv[faces])
    areas = shapely.area(tris)
    if not (np.all(shapely.is_ccw(shapely.get_exterior_ring(tris))) and np.all(areas > 0)):
        return False
    return shapely.union_all(tris).area >= (1 - 1e-9) * areas.sum()


def drawing_shift(msp, pattern, layer: str) -> np.ndarray:
    """(2,) the one translation a DXF writer moved a laid-out (or one-panel) pattern by, to put the
    drawing in the first quadrant: the lower-left corner of ``layer``'s polylines (the seam lines: SEW,
    or CUT without an allowance) less that of the panels' boundary loops."""
    pts = []
    for e in msp.query(f'LWPOLYLINE POLYLINE[layer=="{layer}"]'):
        if e.dxftype() == "LWPOLYLINE":
            pts.append(np.array([p[:2] for p in e.get_points("xy")]))
        else:
            pts.append(np.array([tuple(v.dxf.location)[:2] for v in e.vertices]))
    uv = np.vstack([p.uv[np.concatenate(p.loops)] for p in pattern.panels])
    return np.vstack(pts).min(axis=0) - uv.min(axis=0)


def small_disk(path: Path, size: str, *options) -> None:
    """Mount a tmpfs of ``size`` (``"120k"``) at ``path`` (made here): a disk that fills up; the test is
    skipped where mounting is not allowed.  The caller unmounts it."""
    path.mkdir()
    proc = subprocess.run(["mount", "-t", "tmpfs", "-o", ",".join([f"size={size}", *options]), "tmpfs", str(path)],
                          capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        pytest.skip(f"cannot mount a small file system here ({proc.stderr.strip()})")


def is_dashed(doc, linetype: str) -> bool:
    """True when a DXF linetype draws dashes with gaps between them (a group-49 element below zero)."""
    entry = doc.linetypes.get(linetype)
    return entry is not None and any(t.code == 49 and t.value < 0 for t in entry.pattern_tags.tags)
