"""Imports a subfit control.usda into Blender (bpy from PyPI) the way a user does —
`bpy.ops.wm.usd_import(filepath=..., import_subdivision=True)` — and checks the result:
one mesh object with the cage's vertex (and face) count, a Subdivision Surface modifier
(for Catmull-Clark cages), and crease values on the tagged edges and corners.

Prints one JSON line and exits 1 with the reasons when a check fails, 2 when bpy is missing.

Usage: python3 blender_usd.py CONTROL.usda --vertices N [--faces F] [--subsurf yes|no]
       [--crease A-B]... [--corner V]...
"""

import argparse
import json
import sys


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("usda")
    parser.add_argument("--vertices", type=int, required=True)
    parser.add_argument("--faces", type=int)
    parser.add_argument("--subsurf", choices=["yes", "no"], default="yes")
    parser.add_argument("--crease", action="append", default=[])
    parser.add_argument("--corner", action="append", type=int, default=[])
    args = parser.parse_args()
    try:
        import bpy
    except ImportError:
        print("bpy (pip install bpy==5.0.1) is not installed", file=sys.stderr)
        return 2
    bpy.ops.wm.read_factory_settings(use_empty=True)
    status = bpy.ops.wm.usd_import(filepath=args.usda, import_subdivision=True)
    failures = []
    meshes = [o for o in bpy.data.objects if o.type == "MESH"]
    result = {"import": sorted(status), "mesh_objects": len(meshes)}
    if "FINISHED" not in status:
        failures.append(f"usd_import returned {status}")
    if len(meshes) != 1:
        failures.append(f"{len(meshes)} mesh objects, expected 1")
    if meshes:
        obj = meshes[0]
        me = obj.data
        modifiers = [m.type for m in obj.modifiers]
        result.update(
            vertices=len(me.vertices),
            faces=len(me.polygons),
            modifiers=modifiers,
        )
        if len(me.vertices) != args.vertices:
            failures.append(f"{len(me.vertices)} vertices, expected {args.vertices}")
        if args.faces is not None and len(me.polygons) != args.faces:
            failures.append(f"{len(me.polygons)} faces, expected {args.faces}")
        has_subsurf = "SUBSURF" in modifiers
        if has_subsurf != (args.subsurf == "yes"):
            failures.append(f"modifiers {modifiers}: SUBSURF expected {args.subsurf}")
        edge_crease = {}
        if "crease_edge" in me.attributes:
            for e, d in zip(me.edges, me.attributes["crease_edge"].data):
                if d.value > 0:
                    a, b = e.vertices
                    edge_crease[(min(a, b), max(a, b))] = d.value
        vert_crease = {}
        if "crease_vert" in me.attributes:
            for i, d in enumerate(me.attributes["crease_vert"].data):
                if d.value > 0:
                    vert_crease[i] = d.value
        result.update(creased_edges=len(edge_crease), creased_vertices=len(vert_crease))
        for spec in args.crease:
            a, b = (int(x) for x in spec.split("-"))
            if edge_crease.get((min(a, b), max(a, b)), 0.0) <= 0.0:
                failures.append(f"edge {a}-{b} has no crease")
        for v in args.corner:
            if vert_crease.get(v, 0.0) <= 0.0:
                failures.append(f"vertex {v} has no corner crease")
        untagged = len(edge_crease) - len(args.crease)
        if args.crease and untagged > 0:
            failures.append(f"{untagged} creased edges that were not tagged")
    result["failures"] = failures
    print(json.dumps(result))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
