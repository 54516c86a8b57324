"""From a build123d part to a cutting pattern, in a script.

    python examples/build123d_part.py [OUTPUT_FOLDER]

A sheet-metal hood: a box with its front top edge rounded and a pocket in the
top.  Every face of the solid becomes a panel (its skin, as sheet); the pattern
is checked, drawn and written for a laser cutter.
"""

import sys
from pathlib import Path

import build123d as bd

import patterns

out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
out.mkdir(parents=True, exist_ok=True)

# The part, in millimetres: 300 x 200 x 120, the front top edge rounded (R 60),
# a 50 mm pocket, 20 deep, in the top.
hood = bd.Box(300, 200, 120)
hood = bd.fillet(hood.edges().filter_by(bd.Axis.X).sort_by(bd.Axis.Z)[-1], radius=60)
hood -= bd.Pos(0, -30, 60) * bd.Cylinder(25, 40)

model = patterns.load(hood, max_edge=6)                  # panels = faces, seams = shared edges
pattern = patterns.flatten(model)                         # 1:1, never rescaled
report = patterns.check(pattern, max_strain=0.001)        # sheet metal: 0.1 % at most

print(model)
for panel in report.panels:
    print(f"{panel.name}: {panel.area_flat:9.1f} mm2 flat, strain max {100 * panel.strain_max:.4f} %")
print("ok" if report.ok else "\n".join(f.message for f in report.findings))

patterns.write(pattern, out / "hood.dxf")                 # machine profile: CUT, NOTCH, LABEL, ...
patterns.write(pattern, out / "hood.json", max_strain=0.001)  # the report, in the DXF's frame
patterns.heat_map(pattern, out / "hood.png")
print(f"wrote {out / 'hood.dxf'}, {out / 'hood.json'}, {out / 'hood.png'}")
