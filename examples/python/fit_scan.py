"""Fit a subdivision surface to a scan and write the outputs of ``subfit fit``.

    python examples/python/fit_scan.py scan.ply [-o out] [--tolerance 5e-4] [--max-control-points 5000]

Without a file, fits a sampled ellipsoid (semi-axes 0.25, 0.5, 1.0).
"""

import argparse

import numpy as np

import subfit


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scan", nargs="?", help="a point cloud or mesh (PLY, OBJ, OFF, STL, XYZ)")
    ap.add_argument("-o", "--output", default="subfit-fit")
    ap.add_argument("--tolerance", type=float, default=5e-4, help="E_rms, unit-cube units")
    ap.add_argument("--max-control-points", type=int, default=5000)
    ap.add_argument("--scheme", default="loop", choices=["loop", "catmull-clark", "auto"])
    a = ap.parse_args()

    if a.scan:
        scan = subfit.read(a.scan)
        points, faces, normals, name = scan.vertices, scan.faces, scan.normals, a.scan
    else:
        rng = np.random.default_rng(0)
        d = rng.normal(size=(30000, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        points, faces, normals, name = d * [0.25, 0.5, 1.0], None, None, "ellipsoid"
    print(f"{name}: {len(points)} points" + (f", {len(faces)} faces" if faces is not None else ""))

    def progress(e: dict) -> None:
        if e["event"] == "stage":
            print(f"  stage {e['stage']}: λ={e['lambda']:.0e}, {e['control_points']} control points")

    fit = subfit.fit(points, faces=faces, normals=normals, scheme=a.scheme, tolerance=a.tolerance,
                     max_control_points=a.max_control_points, name=name, progress=progress)
    print(fit.summary)
    out = fit.save(a.output)
    two = fit.report["final"]["two_sided"]
    print(f"{fit.num_control_points} control points, two-sided E_rms {two['e_rms']:.2e}, "
          f"E_max {two['e_max']:.2e} (unit cube); wrote {out}/")
    surf = fit.surface()
    vertices, tris = surf.tessellation(level=3)  # e.g. trimesh.Trimesh(vertices, tris)
    print(f"limit tessellation: {len(vertices)} vertices, {len(tris)} faces")


if __name__ == "__main__":
    main()
