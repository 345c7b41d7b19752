"""BlockLODContour on a volume split across MPI ranks: one seamless surface.

Three ways to run it (TestBlockLODContourMPI* in Testing/CMakeLists.txt):
  pvbatch --no-mpi TestBlockLODContourMPI.py --out ref.json        (the reference)
  mpiexec -n 2 pvbatch TestBlockLODContourMPI.py --reference ref.json
  pvpython TestBlockLODContourMPI.py --port P --reference ref.json  (an MPI pvserver)

For each level of detail 0..3 it fetches the whole surface to this process
(the ranks' pieces appended, points not merged) and measures: triangles, total
area, triangles that occur more than once (by vertex positions), boundary
edges after merging coincident points (a crack between pieces would add
some), the set of triangles with their block ids (a hash of the sorted list)
and the ranks that produced triangles. With --reference every figure must
equal the one-process run's: same triangles, none duplicated, no new boundary.
--representation is where a representation-based variant (the GPU mapper's
parallel image) plugs in; this script checks BlockLODContour's geometry.
"""
import argparse
import hashlib
import json
import os
import sys

import numpy as np
from paraview import servermanager
import paraview.simple as simple
from vtkmodules.util.numpy_support import vtk_to_numpy

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--plugin", default=os.environ.get("MEDISO_PLUGIN", ""))
parser.add_argument("--port", type=int, default=0, help="connect to a pvserver on this port")
parser.add_argument("--host", default="localhost")
parser.add_argument("--plugin-on-server-path", action="store_true")
parser.add_argument("--out", help="write the figures as JSON")
parser.add_argument("--reference", help="compare with this JSON (a one-process run)")
parser.add_argument("--dims", type=int, nargs=3, default=[93, 86, 79])
parser.add_argument("--isovalue", type=float, default=400.5,
                    help="off the int16 values, so no sample equals it (no degenerate triangles)")
parser.add_argument("--representation", default="Surface")
args, _ = parser.parse_known_args()

ns = {"__name__": "medical_isosurfaces_proxies"}
if args.port:
    simple.Connect(args.host, args.port, timeout=30)
if args.port and args.plugin_on_server_path:
    simple._add_functions(ns)
else:
    simple.LoadPlugin(args.plugin, remote=bool(args.port), ns=ns)

ranks = servermanager.ActiveConnection.GetNumberOfDataPartitions()
phantom = ns["MedicalPhantom"](Dimensions=args.dims, Spacing=[0.9, 1.1, 1.3],
                               Origin=[-7.0, 3.0, 11.0], NoiseStandardDeviation=15.0, Seed=7)
contour = ns["BlockLODContour"](Input=phantom, ContourBy=["POINTS", "HU"],
                                Isosurfaces=[args.isovalue], GenerateBlockIds=1)
pids = simple.ProcessIdScalars(Input=contour)


def figures(surface):
    points = vtk_to_numpy(surface.GetPoints().GetData()).astype(np.float64)
    polys = surface.GetPolys()
    conn = vtk_to_numpy(polys.GetConnectivityArray()).reshape(-1, 3)
    offsets = vtk_to_numpy(polys.GetOffsetsArray())
    assert np.all(np.diff(offsets) == 3), "triangles only"
    blocks = vtk_to_numpy(surface.GetCellData().GetArray("BlockId")).astype(np.int64)
    process = surface.GetPointData().GetArray("ProcessId")
    ranks_used = sorted(set(int(r) for r in np.unique(vtk_to_numpy(process)))) if process else []
    a, b, c = points[conn[:, 0]], points[conn[:, 1]], points[conn[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    # Points by position (quantised to 1e-4 of a unit): the pieces' copies of
    # a shared point become one.
    q = np.round(points * 1e4).astype(np.int64)
    _, merged = np.unique(q, axis=0, return_inverse=True)
    merged = merged.reshape(-1)
    tri = np.sort(merged[conn], axis=1)
    # Triangles as sorted position triples: duplicates, and a hash of the set.
    keyed = np.sort(np.stack([q[conn[:, 0]], q[conn[:, 1]], q[conn[:, 2]]], axis=1)
                    .reshape(len(conn), 3, 3), axis=1).reshape(len(conn), 9)
    with_block = np.concatenate([keyed, blocks[:, None]], axis=1)
    order = np.lexsort(with_block.T[::-1])
    ordered = with_block[order]
    _, counts = np.unique(keyed, axis=0, return_counts=True)
    duplicates = int((counts - 1).sum())
    edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [0, 2]]])
    _, edge_counts = np.unique(edges, axis=0, return_counts=True)
    return {
        "triangles": int(len(conn)),
        "area": float(area),
        "duplicate_triangles": duplicates,
        "boundary_edges": int((edge_counts == 1).sum()),
        "nonmanifold_edges": int((edge_counts > 2).sum()),
        "hash": hashlib.sha1(np.ascontiguousarray(ordered).tobytes()).hexdigest(),
        "ranks_with_triangles": ranks_used,
    }


result = {"ranks": ranks, "dims": args.dims, "levels": {}}
for level in range(4):
    contour.LOD = level
    surface = servermanager.Fetch(pids)
    result["levels"][str(level)] = figures(surface)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)

check = Checks()


print("%d rank(s), phantom %s, isovalue %g" % (ranks, "x".join(map(str, args.dims)), args.isovalue))
print("| level | triangles | area | duplicates | boundary edges | non-manifold edges "
      "| ranks with triangles | same triangles as 1 process |")
print("|---:|---:|---:|---:|---:|---:|---|---|")
reference = None
if args.reference:
    with open(args.reference) as f:
        reference = json.load(f)
for level in range(4):
    mine = result["levels"][str(level)]
    same = "-"
    if reference:
        ref = reference["levels"][str(level)]
        same = "yes" if mine["hash"] == ref["hash"] else "NO"
        tag = "level %d, %d ranks" % (level, ranks)
        check(mine["triangles"] == ref["triangles"], "%s: %d triangles, one process %d"
              % (tag, mine["triangles"], ref["triangles"]))
        check(abs(mine["area"] - ref["area"]) <= 1e-9 * ref["area"], "%s: area %.9g, one process %.9g"
              % (tag, mine["area"], ref["area"]))
        check(mine["hash"] == ref["hash"], "%s: the triangles (with block ids) are the "
              "one-process triangles" % tag)
        check(mine["duplicate_triangles"] == ref["duplicate_triangles"],
              "%s: no duplicate triangles at piece boundaries (%d, one process %d)"
              % (tag, mine["duplicate_triangles"], ref["duplicate_triangles"]))
        check(mine["boundary_edges"] == ref["boundary_edges"],
              "%s: no cracks: %d boundary edges, one process %d"
              % (tag, mine["boundary_edges"], ref["boundary_edges"]))
        check(len(mine["ranks_with_triangles"]) == ranks,
              "%s: every rank made a part of the surface (%s)" % (tag, mine["ranks_with_triangles"]))
    print("| %d | %d | %.6g | %d | %d | %d | %s | %s |" % (
        level, mine["triangles"], mine["area"], mine["duplicate_triangles"],
        mine["boundary_edges"], mine["nonmanifold_edges"],
        ",".join(map(str, mine["ranks_with_triangles"])), same))
    check(mine["triangles"] > 100, "level %d has a surface" % level)
    check(mine["duplicate_triangles"] == 0, "level %d: no triangle occurs twice" % level)
if reference:
    check(ranks > 1 and reference["ranks"] == 1, "the run is parallel and the reference is not")
if args.out:
    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)
if args.port:
    simple.Disconnect()
check.finish("BlockLODContour MPI (%d ranks): all checks passed" % ranks)
