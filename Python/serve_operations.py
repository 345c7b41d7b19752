"""The web server's volumes and its operations on a surface (docs/web.md, "The server").

    pvpython --no-mpi Python/serve_operations.py --plugin MedicalIsosurfaces.so --results DIR \\
        [--export DIR] SOURCE [SOURCE ...]

SOURCE is a volume file (MetaImage, VTK XML image, NIfTI .nii/.nii.gz), a DICOM series folder,
or phantom:N[:noise=HU][:seed=K] (the plugin's MedicalPhantom, N^3 points, with its seeded noise
of standard deviation HU, 0 by default, and seed K, 1 by default: phantom_spec()).
Python/serve.py starts this program as its worker (Python/serve_jobs.py). It opens the volumes
(open_sources(), each announced first with an "opening" line, so that the server can name the
file whose reader ended the process; the readers' errors are captured and said in one "fatal"
line); at the server's start, --export also writes
their values as DIR/dN.npy and describes them in the "ready" line, so that no reader ever runs in
the server. Then one JSON line per job on stdin, JSON lines back on stdout (progress, then done,
error or cancelled); SIGUSR1 cancels the job that runs. A job extracts the page's surface with
the plugin's BlockLODContour (same volume, isovalue and level), applies the steps (smooth,
fillHoles, clip, decimate) with VTK's filters, and writes the result as binary STL, binary
little-endian PLY and appended-binary VTP, named by the job's result id, into the results folder.

A process of its own, not a thread of the web server: VTK's Python wrappers keep the GIL while a
filter runs, so a VTK thread would stop the server's event loop (every page, every other browser)
for as long as the filter takes. Here the server stays responsive, and a crash or a filter that
ignores abort costs only this process, which the server restarts.
"""
import argparse
import json
import os
import shutil
import signal
import sys
import time
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

PHANTOM = "phantom:"
PHANTOM_EXTENT_MM = 192.0
PHANTOM_DEFAULT = PHANTOM + "192"
FORMATS = ("stl", "ply", "vtp")
NIFTI_SUFFIXES = (".nii", ".nii.gz", ".hdr", ".img", ".hdr.gz", ".img.gz")


def default_sources():
    """The fetched head CT, else the phantom: what the server opens without --data."""
    from fetch_data import resolve_cache_dir
    ct = resolve_cache_dir(None) / "ct_head.mha"
    return [str(ct)] if ct.is_file() else [PHANTOM_DEFAULT]


def _has_dicom_files(folder):
    """True when the folder holds at least one file with DICOM's 'DICM' preamble."""
    for entry in sorted(os.listdir(folder)):
        path = os.path.join(folder, entry)
        try:
            with open(path, "rb") as f:
                if f.read(132)[128:132] == b"DICM":
                    return True
        except OSError:
            continue
    return False


def _producer(image, name):
    """A TrivialProducer proxy holding an image read by VTK directly (builtin session)."""
    import paraview.simple as simple
    producer = simple.TrivialProducer(registrationName=name)
    producer.GetClientSideObject().SetOutput(image)
    return producer


def phantom_spec(spec):
    """(N, noise, seed) of phantom:N[:noise=HU][:seed=K]: the plugin's MedicalPhantom at N^3
    points (2-1024) with NoiseStandardDeviation HU (0-10000, its range; 0: none, the default)
    and Seed K (1 by default), e.g. phantom:512:noise=40 for the issues' noisy phantom.
    Raises ValueError with a message for the user."""
    size, *options = spec[len(PHANTOM):].split(":")
    try:
        n = int(size)
    except ValueError:
        n = 0
    if not 2 <= n <= 1024:
        raise ValueError("%s: the phantom's size is an integer 2-1024" % spec)
    noise, seed = 0.0, 1
    for option in options:
        key, _, value = option.partition("=")
        try:
            if key == "noise":
                noise = float(value)
                if not 0 <= noise <= 10000:  # rejects NaN too
                    raise ValueError
            elif key == "seed":
                seed = int(value)
                if not -2 ** 31 <= seed < 2 ** 31:
                    raise ValueError
            else:
                raise KeyError
        except KeyError:
            raise ValueError("%s: a phantom's options are noise=HU and seed=N (%r is neither)"
                             % (spec, option))
        except ValueError:
            raise ValueError("%s: noise is a number of HU from 0 to 10000, seed an integer (%r)"
                             % (spec, option))
    return n, noise, seed


def open_reader(spec, ns):
    """A ParaView source for SOURCE, its display name and a note on the reader used.

    ns holds the plugin's proxies (MedicalPhantom, BlockLODContour, and the readers the plugin
    has: MedicalNIfTIReader for .nii.gz, MedicalDICOMSeriesReader for a series in patient space).
    Raises ValueError with a message for the user when SOURCE cannot be opened.
    """
    import paraview.simple as simple
    if spec.startswith(PHANTOM):
        n, noise, seed = phantom_spec(spec)
        phantom = ns["MedicalPhantom"](Dimensions=[n, n, n], Spacing=[PHANTOM_EXTENT_MM / n] * 3,
                                       NoiseStandardDeviation=noise, Seed=seed)
        name = "MedicalPhantom %d^3" % n + (", noise %g HU (seed %d)" % (noise, seed) if noise else "")
        return phantom, name, "the plugin's MedicalPhantom"
    path = os.path.abspath(spec)
    name = os.path.basename(os.path.normpath(path))
    if os.path.isdir(path):
        if not _has_dicom_files(path):
            raise ValueError("%s: a folder, but it holds no DICOM files" % spec)
        if "MedicalDICOMSeriesReader" in ns:
            return ns["MedicalDICOMSeriesReader"](FileName=path), name, "MedicalDICOMSeriesReader"
        return (simple.DICOMReaderdirectory(FileName=path), name,
                "ParaView's DICOM reader (origin 0, rows and slices as vtkDICOMImageReader "
                "orders them: the plugin's MedicalDICOMSeriesReader places a series in "
                "patient space)")
    if not os.path.isfile(path):
        raise ValueError("%s: no such file or folder" % spec)
    lower = path.lower()
    if lower.endswith(NIFTI_SUFFIXES):
        if "MedicalNIfTIReader" in ns:
            return ns["MedicalNIfTIReader"](FileName=path), name, "MedicalNIfTIReader"
        # ParaView 5.11's own NIfTI reader (the AnalyzeNIfTIReaderWriter plugin) reads only
        # uncompressed files; VTK's reader reads both.
        from vtkmodules.vtkIOImage import vtkNIFTIImageReader
        reader = vtkNIFTIImageReader()
        if not reader.CanReadFile(path):
            raise ValueError("%s: not a NIfTI file VTK can read" % spec)
        reader.SetFileName(path)
        reader.Update()
        return (_producer(reader.GetOutput(), name), name,
                "VTK's vtkNIFTIImageReader (origin 0, no sform/qform; header scaling not applied)")
    reader = simple.OpenDataFile(path)
    if reader is None:
        raise ValueError("%s: ParaView has no reader for this file" % spec)
    return reader, name, reader.GetXMLLabel()


def image_of(source, name):
    """The source's vtkImageData (builtin session) and the array to contour, checked."""
    source.UpdatePipeline()
    image = source.GetClientSideObject().GetOutputDataObject(0)
    if image is None or not image.IsA("vtkImageData"):
        raise ValueError("%s: not a 3D image (%s)" % (name, image.GetClassName() if image else
                                                      "nothing was read"))
    dims = image.GetDimensions()
    if min(dims) < 2:
        raise ValueError("%s: %s points is not a 3D volume" % (name, "x".join(map(str, dims))))
    data = image.GetPointData()
    array = data.GetScalars()
    if array is None or array.GetNumberOfComponents() != 1:
        ones = [data.GetArray(i) for i in range(data.GetNumberOfArrays())
                if data.GetArray(i) is not None and data.GetArray(i).GetNumberOfComponents() == 1]
        if not ones:
            raise ValueError("%s: no one-component point array to contour" % name)
        array = ones[0]
    if not array.GetName():
        array.SetName("scalars")
    return image, array


# The scalar types the page reads (numpy's names, as /api/datasets states them): the cores'
# types, which the WebAssembly module hands the page (TestWebPage_budget checks the two agree).
SCALAR_TYPES = ("int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64")


def quietly(function):
    """function() with VTK's messages and the process's stderr captured.

    Returns (its value, [VTK errors], [warnings]); stdout and stderr are both captured. A reader's VTK errors, and what MetaImage's
    library (metaio) writes to std::cerr when it cannot read a file's data (it returns a
    zero-filled volume and raises no VTK error), are errors; any other text it writes is a
    warning. Whatever the reader prints while it crashes goes to the capture as well, so the
    server says one line instead of a stack trace.
    """
    from vtkmodules.vtkCommonCore import vtkLogger, vtkOutputWindow, vtkStringOutputWindow
    import tempfile
    capture = vtkStringOutputWindow()
    previous = vtkOutputWindow.GetInstance()
    verbosity = vtkLogger.GetCurrentVerbosityCutoff()
    vtkOutputWindow.SetInstance(capture)
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    with tempfile.TemporaryFile() as stderr:
        os.dup2(stderr.fileno(), 1)
        os.dup2(stderr.fileno(), 2)
        try:
            value = function()
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            for fd, copy in zip((1, 2), saved):
                os.dup2(copy, fd)
                os.close(copy)
            vtkOutputWindow.SetInstance(previous)
            vtkLogger.SetStderrVerbosity(verbosity)
        stderr.seek(0)
        printed = stderr.read().decode("utf-8", "replace")
    errors, warnings = [], []
    lines = capture.GetOutput().splitlines()
    for i, line in enumerate(lines):
        kind = errors if line.startswith("ERROR") else warnings if line.startswith("Warning") \
            else None
        if kind is not None:
            following = [n for n in lines[i + 1:i + 3] if n.strip()]
            kind.append(_last_line(following[0] if following else line))
    printed = [line.strip() for line in printed.splitlines() if line.strip()]
    if any(line.startswith("Meta") for line in printed):
        errors.append(" ".join(printed))
    elif printed:
        warnings.append(" ".join(printed))
    return value, errors, warnings


def open_sources(specs, ns, log, opening=None):
    """[(source proxy, name, vtkImageData, vtkDataArray)] for the specs, in their order.

    Raises ValueError with one line for the user when a spec cannot be read; the reader's own
    errors are captured and said in that line. opening(i) is called before spec i is read.
    """
    opened = []
    for i, spec in enumerate(specs):
        if opening is not None:
            opening(i)

        def read():
            source, name, note = open_reader(spec, ns)
            return (source, name, note) + image_of(source, spec)

        (source, name, note, image, array), errors, warnings = quietly(read)
        if errors:
            raise ValueError("%s: %s" % (spec, errors[0]))
        for warning in warnings:
            log("%s: the reader warns: %s" % (name, warning))
        log("%s: read with %s" % (name, note))
        opened.append((source, name, image, array))
    return opened


def source_format(spec):
    """{"name", "space"}: the source's format and the patient space its world coordinates are in
    (the page places the volume by it, docs/web.md "Orientation"): NIfTI's RAS; DICOM's LPS;
    MetaImage's LPS (ITK's convention, which writes its TransformMatrix in LPS); the plugin's
    phantom, built in NIfTI's frame, RAS; any other file LPS, as ITK takes it."""
    if spec.startswith(PHANTOM):
        return {"name": "phantom", "space": "RAS"}
    if os.path.isdir(spec):
        return {"name": "DICOM", "space": "LPS"}
    lower = spec.lower()
    if lower.endswith(NIFTI_SUFFIXES):
        return {"name": "NIfTI", "space": "RAS"}
    if lower.endswith((".mha", ".mhd")):
        return {"name": "MetaImage", "space": "LPS"}
    if lower.endswith(".vti"):
        return {"name": "VTK image", "space": "LPS"}
    return {"name": os.path.splitext(lower)[1].lstrip(".") or "unknown", "space": "LPS"}


def source_modified(spec):
    """When the source's file (a series' newest file) last changed, in seconds since the epoch;
    None for the phantom."""
    if spec.startswith(PHANTOM):
        return None
    if os.path.isdir(spec):
        times = [os.path.getmtime(os.path.join(spec, n)) for n in os.listdir(spec)
                 if os.path.isfile(os.path.join(spec, n))]
        return max(times) if times else os.path.getmtime(spec)
    return os.path.getmtime(spec)


def metaimage_direction(spec):
    """The direction matrix a MetaImage header states (TransformMatrix, row-major, columns =
    axes), or None. VTK's and ParaView's MetaImage readers leave it out (their images have the
    identity), as ITK and 3D Slicer do not: the server states it to the page, which places the
    volume in patient space by it; the worker's image keeps VTK's identity, so that its surfaces
    are in the frame the page draws in."""
    try:
        with open(spec, "rb") as f:
            for _ in range(64):
                key, sep, value = f.readline().decode("ascii", "replace").partition("=")
                key = key.strip()
                if not sep or key == "ElementDataFile":
                    return None
                if key in ("TransformMatrix", "Rotation", "Orientation"):
                    # row by row, the axes as columns (as Headless/MetaImage.cxx reads it)
                    t = [float(v) for v in value.split()]
                    return t if len(t) == 9 else None
    except (OSError, ValueError):
        return None
    return None


def describe(spec, name, image, array):
    """What the server needs of a volume, besides its values: its geometry, type and range."""
    import math
    lo, hi = array.GetRange()
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo >= hi:
        raise ValueError("%s: its values span no range (%g..%g)" % (spec, lo, hi))
    matrix = image.GetDirectionMatrix()
    direction = [matrix.GetElement(r, c) for r in range(3) for c in range(3)]
    if source_format(spec)["name"] == "MetaImage":
        direction = metaimage_direction(spec) or direction
    return {"name": name, "dims": list(image.GetDimensions()), "spacing": list(image.GetSpacing()),
            "origin": list(image.GetOrigin()), "direction": direction,
            "range": [float(lo), float(hi)], "format": source_format(spec),
            "modified": source_modified(spec)}


def export(index, spec, name, image, array, folder):
    """The volume's values as FOLDER/dINDEX.npy (z, y, x) for the server, and its description."""
    import numpy
    from vtkmodules.util.numpy_support import vtk_to_numpy
    values = vtk_to_numpy(array)
    if values.dtype.name not in SCALAR_TYPES:
        raise ValueError("%s: %s values are not supported" % (spec, array.GetDataTypeAsString()))
    description = describe(spec, name, image, array)
    dims = description["dims"]
    path = os.path.join(folder, "d%d.npy" % index)
    numpy.save(path, values.reshape(dims[2], dims[1], dims[0]))
    return dict(description, type=values.dtype.name, values=path)


# ------------------------------------------------------------------------------- export and report
def padded(image, array, pad, value):
    """The image with `pad` more samples of `value` on every side (same spacing and type), so
    that a contour of it closes where the volume's box cut the surface (docs/web.md, "Export").
    Level k samples the points at multiples of its stride from the first: a pad of that stride
    keeps the level's lattice on the volume's own samples."""
    import numpy
    from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
    from vtkmodules.vtkCommonDataModel import vtkImageData
    nx, ny, nz = image.GetDimensions()
    values = numpy.pad(vtk_to_numpy(array).reshape(nz, ny, nx), pad, constant_values=value)
    extent = image.GetExtent()
    spacing = image.GetSpacing()
    matrix = image.GetDirectionMatrix()
    # index i' = i + pad: origin' = origin + D ((extent start - pad) x spacing)
    shift = [(extent[2 * a] - pad) * spacing[a] for a in range(3)]
    origin = [image.GetOrigin()[r] + sum(matrix.GetElement(r, c) * shift[c] for c in range(3))
              for r in range(3)]
    out = vtkImageData()
    out.SetDimensions(nx + 2 * pad, ny + 2 * pad, nz + 2 * pad)
    out.SetSpacing(spacing)
    out.SetOrigin(origin)
    out.SetDirectionMatrix(matrix)
    scalars = numpy_to_vtk(values.ravel(), deep=True, array_type=array.GetDataType())
    scalars.SetName(array.GetName())
    out.GetPointData().SetScalars(scalars)
    return out


def scene_frame(image):
    """The image in the page's scene frame (origin + index x spacing, its direction left out:
    docs/web.md, "Orientation"), or None when it has no direction. BlockLODContour places a
    surface by the image's direction, as VTK's contour filters do; the page draws the server's
    results in its scene frame, so the operations contour the image without it."""
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkCommonMath import vtkMatrix3x3
    if image.GetDirectionMatrix().IsIdentity():
        return None
    out = vtkImageData()
    out.ShallowCopy(image)
    out.SetDirectionMatrix(vtkMatrix3x3())  # a new matrix: the source's own stays as it is
    return out


def _float_points(mesh):
    """The mesh with float32 points, as the STL holds them (positions equal in float32 are one
    corner there, even where they differ in double)."""
    from vtkmodules.util.vtkConstants import VTK_FLOAT
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    if mesh.GetPoints().GetDataType() == VTK_FLOAT:
        return mesh
    from vtkmodules.vtkCommonCore import vtkPoints
    points = vtkPoints()
    points.SetDataTypeToFloat()
    points.DeepCopy(mesh.GetPoints())
    points.SetDataTypeToFloat()
    out = vtkPolyData()
    out.SetPoints(points)
    out.SetPolys(mesh.GetPolys())
    return out


def merged(mesh, merge=True):
    """vtkCleanPolyData with tolerance 0: corners at the same position made one point (when
    `merge`), triangles left with fewer than three corners dropped (no line or vertex made of
    them), unused points dropped."""
    from vtkmodules.vtkFiltersCore import vtkCleanPolyData
    f = vtkCleanPolyData()
    f.SetInputData(mesh)
    f.SetTolerance(0.0)
    f.SetPointMerging(merge)
    f.ConvertPolysToLinesOff()
    f.ConvertLinesToPointsOff()
    f.ConvertStripsToPolysOff()
    f.Update()
    return f.GetOutput()


def without_duplicates(mesh):
    """All but the first of the triangles on the same three points (vtkRemoveDuplicatePolys)."""
    from vtkmodules.vtkFiltersCore import vtkRemoveDuplicatePolys
    f = vtkRemoveDuplicatePolys()
    f.SetInputData(mesh)
    f.Update()
    return f.GetOutput()


def edge_counts(mesh):
    """(boundary edges, non-manifold edges) by vtkFeatureEdges."""
    from vtkmodules.vtkFiltersCore import vtkFeatureEdges
    counts = []
    for boundary in (True, False):
        f = vtkFeatureEdges()
        f.SetInputData(mesh)
        f.SetBoundaryEdges(boundary)
        f.SetNonManifoldEdges(not boundary)
        f.FeatureEdgesOff()
        f.ManifoldEdgesOff()
        f.Update()
        counts.append(f.GetOutput().GetNumberOfCells())
    return counts


def components(mesh, largest=False):
    """The number of connected pieces, or (largest=True) the largest piece alone."""
    from vtkmodules.vtkFiltersCore import vtkPolyDataConnectivityFilter
    f = vtkPolyDataConnectivityFilter()
    f.SetInputData(mesh)
    if largest:
        f.SetExtractionModeToLargestRegion()
    else:
        f.SetExtractionModeToAllRegions()
    f.Update()
    return merged(f.GetOutput(), merge=False) if largest else f.GetNumberOfExtractedRegions()


def mesh_report(mesh):
    """serve_messages.REPORT's fields of a triangle mesh, by VTK, as an STL reader would find
    them: corners at the same float32 position are one point."""
    mesh = _float_points(mesh)
    whole = merged(mesh)
    boundary, non_manifold = edge_counts(whole)
    duplicates = whole.GetNumberOfCells() - without_duplicates(whole).GetNumberOfCells()
    return {"triangles": mesh.GetNumberOfCells(), "points": whole.GetNumberOfPoints(),
            "components": components(whole), "boundaryEdges": boundary,
            "nonManifoldEdges": non_manifold,
            "degenerateTriangles": mesh.GetNumberOfCells() - whole.GetNumberOfCells(),
            "duplicateTriangles": duplicates,
            "watertight": whole.GetNumberOfCells() > 0 and boundary == 0 and non_manifold == 0
            and duplicates == 0}


# ---------------------------------------------------------------------------------- the worker
class Cancelled(Exception):
    pass


class JobFailed(Exception):
    pass


class Worker:
    """Runs jobs one at a time on the opened volumes; reports on `out` (JSON lines)."""

    STAGES = ("surface", "smooth", "fillHoles", "clip", "decimate", "export", "report", "write")

    def __init__(self, sources, ns, results, out):
        self.sources = sources
        self.ns = ns
        self.results = results
        self.out = out
        self.contours = {}
        self.cancel = False
        self.job = None
        self.errors = []
        self.warnings = []
        self.last = (0.0, 0.0, None)

    def send(self, message):
        emit(self.out, message, self.results)

    # -- observers: progress, abort, the filters' own errors and warnings
    def report(self, fraction, stage):
        """A progress message, when the stage changed or 2% and 0.1 s have passed."""
        now = time.monotonic()
        last_fraction, last_time, last_stage = self.last
        if stage != last_stage or (fraction - last_fraction >= 0.02 and now - last_time >= 0.1):
            self.last = (fraction, now, stage)
            self.send({"job": self.job, "progress": round(fraction, 4), "stage": stage})

    def watch(self, algorithm, stage, index, count, span=1.0):
        """Observers on a filter: progress (the filter's part of the job: index to index + span
        of count parts), abort on cancel, its errors and warnings."""
        from vtkmodules.util.misc import calldata_type
        from vtkmodules.util.vtkConstants import VTK_STRING

        def progress(caller, _event):
            if self.cancel:
                caller.SetAbortExecute(1)
            else:
                self.report((index + span * caller.GetProgress()) / count, stage)

        @calldata_type(VTK_STRING)
        def error(_caller, _event, text):
            self.errors.append(_last_line(text))

        @calldata_type(VTK_STRING)
        def warning(_caller, _event, text):
            self.warnings.append(_last_line(text))

        algorithm.AddObserver("ProgressEvent", progress)
        algorithm.AddObserver("ErrorEvent", error)
        algorithm.AddObserver("WarningEvent", warning)
        return algorithm

    def run_filter(self, algorithm, stage, index, count, data, span=1.0):
        self.watch(algorithm, stage, index, count, span)
        algorithm.SetInputData(data)
        self.report(index / count, stage)
        algorithm.Update()
        self.check(stage)
        return algorithm.GetOutput()

    def check(self, stage):
        if self.cancel:
            raise Cancelled()
        if self.errors:
            raise JobFailed("%s: %s" % (stage, self.errors[0]))

    # -- the steps
    def contour(self, index, pad=0):
        """One BlockLODContour per dataset (and per pad of a capped surface), kept: its cache
        makes a repeated isovalue free. With a pad, it contours the volume with `pad` samples of
        the data's minimum around it (padded())."""
        if (index, pad) not in self.contours:
            source, name, image, array = self.sources[index]
            flat = scene_frame(image)
            if pad:
                source = _producer(padded(flat or image, array, pad, array.GetRange()[0]),
                                   "%s-padded-%d" % (name, pad))
            elif flat is not None:
                source = _producer(flat, "%s-scene" % name)
            contour = self.ns["BlockLODContour"](Input=source,
                                                ContourBy=["POINTS", array.GetName()],
                                                ComputeNormals=0, AutoLOD=0)
            self.contours[(index, pad)] = contour
        return self.contours[(index, pad)]

    def surface(self, job, count):
        from vtkmodules.vtkCommonDataModel import vtkPolyData
        from serve_messages import LEVEL_STRIDES
        pad = 0
        if job["export"]["cap"]:
            lo = self.sources[job["dataset"]][3].GetRange()[0]
            if not job["isovalue"] > lo:
                raise JobFailed("cap: the isovalue is the data's minimum (%g): nothing lies "
                                "below it to close the surface with" % lo)
            pad = LEVEL_STRIDES[job["level"]]
        contour = self.contour(job["dataset"], pad)
        algorithm = contour.GetClientSideObject()
        algorithm.RemoveAllObservers()
        self.watch(algorithm, "surface", 0, count)
        algorithm.SetAbortExecute(0)
        contour.Isosurfaces = [job["isovalue"]]
        contour.LOD = job["level"]
        self.report(0.0, "surface")
        try:
            contour.UpdatePipeline()
            self.check("surface")
        except Cancelled:
            contour.GetClientSideObject().Modified()  # an aborted update is not a result
            raise
        surface = vtkPolyData()
        surface.ShallowCopy(algorithm.GetOutputDataObject(0))
        if surface.GetNumberOfCells() == 0:
            raise JobFailed("no surface at isovalue %g at level %d" % (job["isovalue"],
                                                                       job["level"]))
        return surface

    def step(self, name, params, index, count, data):
        from vtkmodules.vtkCommonDataModel import vtkPlane
        from vtkmodules.vtkFiltersCore import (vtkClipPolyData, vtkDecimatePro,
                                               vtkSmoothPolyDataFilter, vtkTriangleFilter)
        from vtkmodules.vtkFiltersModeling import vtkFillHolesFilter
        if name == "smooth":
            # ParaView's Smooth (Laplacian), with the relaxation factor it leaves at 0.01.
            f = vtkSmoothPolyDataFilter()
            f.SetNumberOfIterations(params["iterations"])
            f.SetRelaxationFactor(params.get("relaxation", 0.01))
            return self.run_filter(f, name, index, count, data)
        if name == "fillHoles":
            f = vtkFillHolesFilter()
            f.SetHoleSize(params["size"])
            filled = self.run_filter(f, name, index, count, data, 0.9)
            return self.run_filter(vtkTriangleFilter(), name, index + 0.9, count, filled, 0.1)
        if name == "clip":
            # ParaView's Clip by a plane keeps the side behind the normal (Invert on).
            plane = vtkPlane()
            plane.SetOrigin(params["origin"])
            plane.SetNormal(params["normal"])
            f = vtkClipPolyData()
            f.SetClipFunction(plane)
            f.InsideOutOn()
            clipped = self.run_filter(f, name, index, count, data, 0.9)
            return self.run_filter(vtkTriangleFilter(), name, index + 0.9, count, clipped, 0.1)
        if name == "decimate":
            # ParaView's Decimate (vtkDecimatePro) with PreserveTopology on: without it the
            # filter splits the mesh at sharp edges and a closed surface comes out with holes.
            f = vtkDecimatePro()
            f.SetTargetReduction(params["reduction"])
            f.PreserveTopologyOn()
            return self.run_filter(f, name, index, count, data)
        raise JobFailed("unknown step %s" % name)

    def apply_export(self, options, index, count, data):
        """The export options (serve_messages.EXPORT): cleaning, then the largest piece."""
        self.report(index / count, "export")
        mesh = _float_points(data)
        if options["clean"]:
            mesh = without_duplicates(merged(mesh))
        self.check("export")
        if options["largestComponent"]:
            mesh = components(mesh, largest=True)
        self.check("export")
        return mesh

    def write(self, rid, surface, index, count):
        from vtkmodules.vtkCommonDataModel import vtkPolyData
        from vtkmodules.vtkIOGeometry import vtkSTLWriter
        from vtkmodules.vtkIOPLY import vtkPLYWriter
        from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter
        self.report(index / count, "write")
        bare = vtkPolyData()  # points and triangles only: the files hold the geometry
        bare.SetPoints(surface.GetPoints())
        bare.SetPolys(surface.GetPolys())
        sizes = {}
        for k, fmt in enumerate(FORMATS):
            if fmt == "stl":
                w = vtkSTLWriter()
                w.SetFileTypeToBinary()
            elif fmt == "ply":
                w = vtkPLYWriter()
                w.SetFileTypeToBinary()
                w.SetDataByteOrderToLittleEndian()
            else:
                w = vtkXMLPolyDataWriter()
                w.SetDataModeToAppended()
                w.EncodeAppendedDataOff()
            path = os.path.join(self.results, "%s.%s" % (rid, fmt))
            part = os.path.join(self.results, "%s-part.%s" % (rid, fmt))
            w.SetFileName(part)
            w.SetInputData(bare)
            self.watch(w, "write", index + k / len(FORMATS), count, 1.0 / len(FORMATS))
            if not w.Write():
                raise JobFailed("write: %s" % (self.errors[0] if self.errors else
                                               "the %s writer failed" % fmt.upper()))
            self.check("write")
            os.replace(part, path)
            sizes[fmt] = os.path.getsize(path)
        return sizes

    def run(self, job):
        self.job = job["job"]
        self.cancel = False
        self.errors, self.warnings = [], []
        self.last = (0.0, 0.0, None)
        start = time.monotonic()
        steps = job["steps"]
        count = len(steps) + 4  # the surface, each step, the export options, the report, files
        stages = []
        try:
            t = time.monotonic()
            surface = self.surface(job, count)
            stages.append({"stage": "surface", "triangles": surface.GetNumberOfCells(),
                           "seconds": round(time.monotonic() - t, 3)})
            for i, step in enumerate(steps):
                (name, params), = step.items()
                t = time.monotonic()
                surface = self.step(name, params, i + 1, count, surface)
                stages.append({"stage": name, "triangles": surface.GetNumberOfCells(),
                               "seconds": round(time.monotonic() - t, 3)})
                if surface.GetNumberOfCells() == 0:
                    raise JobFailed("%s left no triangles" % name)
            t = time.monotonic()
            surface = self.apply_export(job["export"], count - 3, count, surface)
            stages.append({"stage": "export", "triangles": surface.GetNumberOfCells(),
                           "seconds": round(time.monotonic() - t, 3)})
            if surface.GetNumberOfCells() == 0:
                raise JobFailed("export left no triangles")
            self.report((count - 2) / count, "report")
            report = mesh_report(surface)
            self.check("report")
            sizes = self.write(job["rid"], surface, count - 1, count)
            self.send({"job": self.job, "done": True, "result": job["rid"],
                       "triangles": surface.GetNumberOfCells(),
                       "points": surface.GetNumberOfPoints(),
                       "boundaryEdges": report["boundaryEdges"], "report": report,
                       "bounds": [round(b, 4) for b in surface.GetBounds()],
                       "bytes": sizes, "stages": stages, "warnings": self.warnings[:5],
                       "seconds": round(time.monotonic() - start, 3)})
        except Cancelled:
            self.send({"job": self.job, "cancelled": True})
        except JobFailed as e:
            self.send({"job": self.job, "error": str(e)})
        except Exception as e:  # a bug here must not end the worker: say it, go on
            traceback.print_exc()
            self.send({"job": self.job, "error": "internal error: %s: %s" % (type(e).__name__, e)})
        finally:
            for fmt in FORMATS:
                part = os.path.join(self.results, "%s-part.%s" % (job["rid"], fmt))
                if os.path.exists(part):
                    os.remove(part)
            self.job = None


def _last_line(text):
    """The message of a VTK error or warning, without the file and object it came from."""
    lines = [line.strip() for line in str(text).strip().splitlines() if line.strip()]
    message = lines[-1] if lines else str(text)
    if "): " in message and message.startswith("vtk"):
        message = message.split("): ", 1)[1]
    return message


def load_plugin(path, ns):
    import paraview.simple as simple
    try:
        simple.LoadPlugin(path, ns=ns)
    except RuntimeError:  # ParaView's "Problem loading plugin", after its own error message
        pass


def server_gone(results):
    """The end of input, or of output: the server is gone (a worker it replaces it ends with
    SIGKILL instead). Its results go with it, even when it was killed before it could remove them
    itself."""
    shutil.rmtree(results, ignore_errors=True)


def emit(out, message, results):
    """One message to the server; the worker ends quietly when the server is gone."""
    try:
        out.write(json.dumps(message) + "\n")
        out.flush()
    except BrokenPipeError:
        server_gone(results)
        os._exit(0)  # nothing left to flush: the pipe is closed


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--plugin", required=True)
    p.add_argument("--results", required=True, help="folder the results are written to")
    p.add_argument("--export", help="first start: write the volumes' values into this folder "
                   "(dN.npy) and describe them in the ready message")
    p.add_argument("sources", nargs="+")
    args = p.parse_args(argv)

    # Messages go on the original stdout; anything a library prints goes to stderr.
    out = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    sys.stdout = sys.stderr

    worker = None

    def cancel(_signum, _frame):
        if worker is not None:
            worker.cancel = True

    signal.signal(signal.SIGUSR1, cancel)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the server ends this process itself

    def opening(index):  # the server names this source if reading it ends the process
        emit(out, {"opening": index}, args.results)

    notes = []
    try:
        ns = {"__name__": "medical_isosurfaces_proxies"}  # LoadPlugin fills a non-empty dict only
        _, errors, _ = quietly(lambda: load_plugin(args.plugin, ns))
        if "BlockLODContour" not in ns:
            raise ValueError("%s is not the MedicalIsosurfaces plugin%s" % (
                args.plugin, " (%s)" % errors[0] if errors else ""))
        sources = open_sources(args.sources, ns, notes.append, opening)
        volumes = [] if not args.export else [
            export(i, spec, name, image, array, args.export)
            for i, (spec, (_, name, image, array)) in enumerate(zip(args.sources, sources))]
    except ValueError as e:
        emit(out, {"fatal": str(e)}, args.results)
        return 1
    worker = Worker(sources, ns, args.results, out)
    worker.send({"ready": True, "datasets": [s[1] for s in sources], "volumes": volumes,
                 "notes": notes})
    for line in os.fdopen(0, "r"):  # pvpython replaces sys.stdin
        if not line.strip():
            continue
        job = json.loads(line)
        worker.run(job)
    server_gone(args.results)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
