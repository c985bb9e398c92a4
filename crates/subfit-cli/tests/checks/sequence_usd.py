"""Opens a subfit sequence.usda with USD's own Python bindings (usd-core) and prints what a
player sees: the time range, the frame rate, the time samples of the cage's points and their
count per sample, the subdivision scheme. One JSON line; exit 2 when pxr is missing.

Usage: python3 sequence_usd.py SEQUENCE.usda
"""

import json
import sys


def main():
    try:
        from pxr import Usd, UsdGeom
    except ImportError:
        print("usd-core (pip install usd-core) is not installed", file=sys.stderr)
        return 2
    stage = Usd.Stage.Open(sys.argv[1])
    meshes = [UsdGeom.Mesh(p) for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]
    if len(meshes) != 1:
        print(json.dumps({"error": f"{len(meshes)} meshes"}))
        return 1
    mesh = meshes[0]
    points = mesh.GetPointsAttr()
    times = points.GetTimeSamples()
    counts = sorted({len(points.Get(t)) for t in times})
    print(json.dumps({
        "start": stage.GetStartTimeCode(),
        "end": stage.GetEndTimeCode(),
        "fps": stage.GetTimeCodesPerSecond(),
        "samples": len(times),
        "points_per_sample": counts,
        "faces": len(mesh.GetFaceVertexCountsAttr().Get()),
        "scheme": mesh.GetSubdivisionSchemeAttr().Get(),
        "first": list(points.Get(times[0])[0]) if times else None,
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
