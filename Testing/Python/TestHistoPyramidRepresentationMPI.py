"""The 'HistoPyramid Isosurface' representation rendered in parallel.

Run by Testing/Scripts/mpi-pvbatch.sh (TestHistoPyramidRepresentationMPI):
  pvbatch --no-mpi TestHistoPyramidRepresentationMPI.py --out ref.json  (one process)
  mpiexec -n N pvbatch TestHistoPyramidRepresentationMPI.py --reference ref.json

The phantom is split across the ranks (each generates its own extent); each
rank's vtkHistoPyramidIsoMapper draws its piece on its GPU path, and ParaView
composites the ranks' images (depth compositing for the opaque scene, ordered
compositing for the translucent one). The parallel image must match the
one-process image: covered-pixel masks agree on >= 98.5% of the pixels covered
by either and the mean colour difference over pixels covered by both is
<= 12 of 255 (the thresholds of TestHistoPyramidIsoMapperChecks_Reference).
Rank 0 must have drawn part of the surface and not all of it (its primitives
against the one-process count), so a run where one rank drew everything cannot
pass. A new display of the phantom shifted positive starts at the Otsu
threshold of the whole volume, its histogram summed over the ranks.
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from paraview import servermanager  # noqa: E402
import paraview.simple as simple  # noqa: E402
from paraview.modules.vtkRemotingCore import vtkProcessModule  # noqa: E402

import HistoPyramidRepresentationChecks as checks  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--plugin", default=os.environ.get("MEDISO_PLUGIN", ""))
parser.add_argument("--out", help="write the images' paths as JSON (one-process run)")
parser.add_argument("--reference", help="compare with this JSON (the one-process run)")
parser.add_argument("--size", type=int, default=72)
args, _ = parser.parse_known_args()

ns = {"__name__": "medical_isosurfaces_proxies"}
simple.LoadPlugin(args.plugin, ns=ns)
controller = vtkProcessModule.GetProcessModule().GetGlobalController()
rank = controller.GetLocalProcessId()  # pvbatch runs this script on rank 0
ranks = controller.GetNumberOfProcesses()
work = os.path.dirname(os.path.abspath(args.out or args.reference))
check = checks.Checker()

phantom = ns["MedicalPhantom"](Dimensions=[args.size] * 3)
view, display = checks.make_scene(phantom)
results = {}
for case, skin_opacity in (("opaque", 1.0), ("translucent", 0.35)):
    pwf = simple.GetOpacityTransferFunction("HU")
    pwf.Points = [-1000.0, skin_opacity, 0.5, 0.0, -100.0, skin_opacity, 0.5, 0.0,
                  100.0, 1.0, 0.5, 0.0, 3000.0, 1.0, 0.5, 0.0]
    simple.Render(view)
    # What this rank's representation drew (gathered to rank 0 below).
    info = checks.render_info(display)
    name = "%s-%d.png" % (case, ranks if args.reference else 1)
    pixels = checks.screenshot(view, os.path.join(work, name))
    results[case] = os.path.join(work, name)
    results[case + " primitives"] = info["primitives"]
    if rank == 0:
        print("%s, %d rank(s): path %s, %d primitives (rank 0), %.1f%% of the image covered"
              % (case, ranks, info["path"], info["primitives"],
                 100 * checks.foreground_fraction(pixels)))
    check(info["path"] == "gpu", "%s: rank %d drew on the GPU path" % (case, rank))
    if args.reference and rank == 0:
        with open(args.reference) as f:
            reference = json.load(f)
        # pvbatch runs the script on rank 0; the representation's information
        # comes from rank 0's mapper. It must have drawn part of the surface
        # only: the other ranks drew the rest of the one-process primitives.
        whole = reference[case + " primitives"]
        print("  rank 0 drew %d of the one-process %d primitives" % (info["primitives"], whole))
        check(0 < info["primitives"] < whole,
              "%s: rank 0 drew part of the surface, not all of it" % case)
        ref_pixels = checks.read_png(reference[case])
        agreement, diff, either = checks.compare_images(pixels, ref_pixels)
        print("  against one process: %d pixels covered by either, masks agree on %.2f%%, "
              "mean colour difference %.2f" % (either, 100 * agreement, diff))
        check(either > 5000, "%s: the surface covers a good part of the image" % case)
        check(agreement >= 0.985, "%s: covered pixels match the one-process image" % case)
        check(diff <= 12.0, "%s: colours match the one-process image" % case)

# The start of a new display when the histogram is split across the ranks
# (vtkPVMedicalHistogramInformation sums the ranks' counts): the phantom
# shifted positive starts at the Otsu threshold of the whole volume, the value
# a single process finds (TestMedicalIsosurfacesDefaults: 633.78125).
start_phantom = ns["MedicalPhantom"](Dimensions=[48, 48, 48], Spacing=[3.0, 3.0, 3.0])
shifted = simple.Calculator(Input=start_phantom, Function="HU+1024", ResultArrayName="Shifted")
shifted_display = simple.Show(shifted, view)
check(list(shifted_display.IsosurfaceValues) == [633.78125],
      "%d rank(s): the shifted phantom starts at the whole volume's Otsu threshold 633.78125 (got %s)"
      % (ranks, list(shifted_display.IsosurfaceValues)))
simple.Hide(shifted, view)

if args.out and rank == 0:
    with open(args.out, "w") as f:
        json.dump(results, f)
simple.Delete(view)
del view
if check.failures:
    print("%d check(s) failed" % len(check.failures))
    sys.exit(1)
print("HistoPyramid Isosurface, %d rank(s): all checks passed" % ranks)
