"""Python calls of the MedicalIsosurfaces plugin (embedded in it: importable once it is loaded).

The plugin's sources and filters (MedicalPhantom, BlockLODContour, IsosurfaceLabels, the readers)
are ServerManager proxies: ``LoadPlugin(path, ns=globals())`` adds them to ``paraview.simple``
like any filter. What is not a proxy lives here:

``MakeMeshFromView(display=None, view=None, level=None, names=None, show=True)``
    the surfaces a *HistoPyramid Isosurface* display shows, as a mesh to save (File > Save
    Data: STL, PLY, VTP): a Block LOD Contour of the display's input with the display's
    isovalues and array, at ``level`` (0-3; ``None``: the finest level the memory estimator
    fits in the filter's Memory Budget, Auto LOD), followed by Isosurface Labels, which adds
    each triangle's surface index and colour (cell data ``SurfaceIndex``, ``SurfaceColor``)
    and each surface's name, value and colour (field data). The panel's *Make Mesh* button
    runs this function.

``RefineAfterChange(contour, view=None, frame_budget=0.1)``
    isovalue changes of a Block LOD Contour answered coarse first, then refined (issue 30):
    ``change(values, newer=None)`` draws the new isovalues at once at the finest level whose
    extraction (the filter's estimator) and frame (the display's frame-time model) fit in
    ``frame_budget`` seconds together, then updates the filter
    at the level the user set (Auto LOD's memory choice, or LOD) and draws that, unless
    ``newer()``, polled at the filter's progress events (builtin session), says a newer change
    is waiting: the refinement is then aborted (the filter's AbortExecute) and counted, and the
    coarse answer stays shown. ParaView 5.11's update is synchronous: the refinement blocks the
    caller while it runs (docs/blocklod.md).

``RefineHistoPyramidChange(display, values, view=None)``
    an isovalue change of a *HistoPyramid Isosurface* display drawn first by an interactive
    render (a coarse volume level or sample distance within the display's interactive budget,
    only that level's pyramid built), then by the still render (the full volume).
"""

import math
import time

from paraview import servermanager, simple
from paraview.vtk import vtkDataSetAttributes

#: The representation type the mesh is made from.
REPRESENTATION = "HistoPyramid Isosurface"


def _display_proxy(display, view):
    if display is None:
        source = simple.GetActiveSource()
        if source is None:
            raise ValueError("MakeMeshFromView: no active source; pass the display.")
        display = simple.GetDisplayProperties(source, view)
    return display


def _contoured_array(display, source, port):
    """The array the display contours (its colouring array, else the input's active point
    scalars) and its range ((name, None) when the data information has no such array)."""
    info = source.GetDataInformation(port).DataInformation.GetPointDataInformation()
    name = display.ColorArrayName[1] if display.ColorArrayName[0] in ("POINTS", "") else ""
    array = info.GetArrayInformation(name) if name else \
        info.GetAttributeInformation(vtkDataSetAttributes.SCALARS)
    if array is None:
        return name, None
    return array.GetName(), array.GetComponentRange(0)


def _format(value):
    return ("%.6g" % value)


def MakeMeshFromView(display=None, view=None, level=None, names=None, show=True):
    """Returns the IsosurfaceLabels proxy of the mesh of ``display``'s surfaces (see the module).

    ``display``: a display shown as HistoPyramid Isosurface (default: the active source's in
    ``view``); ``view``: its view (default: the active view), rendered once so that the colours
    are those drawn; ``level``: 0-3, or None for Auto LOD; ``names``: one name per isovalue
    (default: the array's name and the value, e.g. "HU 400"); ``show``: show the mesh in ``view``
    coloured by surface (a categorical colour map of its own: the surfaces' names, colours and
    opacities) and hide the display, as a filter's Apply replaces its input.
    Surfaces the display does not draw (opacity 0, values outside the array's range or not
    numbers) are left out.
    """
    if view is None:
        view = simple.GetActiveView()
    display = _display_proxy(display, view)
    if display.GetProperty("Representation") is None or display.Representation != REPRESENTATION:
        raise ValueError("MakeMeshFromView: the display is not shown as %s." % REPRESENTATION)
    if level is not None and level not in (0, 1, 2, 3):
        raise ValueError("MakeMeshFromView: level must be 0, 1, 2, 3 or None (Auto LOD), not %r."
                         % (level,))
    input_property = display.GetProperty("Input")
    source = servermanager._getPyProxy(input_property.GetProxy(0))
    port = input_property.GetOutputPortForConnection(0)
    array, data_range = _contoured_array(display, source, port)

    # The colour and opacity each isovalue is drawn with, as of a render.
    if view is not None:
        simple.Render(view)
    display.UpdatePropertyInformation()
    looks = list(display.GetProperty("HistoPyramidSurfaceLooks"))
    isovalues = list(display.IsosurfaceValues)
    if names is not None and len(names) != len(isovalues):
        raise ValueError("MakeMeshFromView: %d names for %d isovalues." % (len(names), len(isovalues)))
    values, colors, labels = [], [], []
    for i, value in enumerate(isovalues):
        look = looks[4 * i:4 * i + 4] if len(looks) >= 4 * (i + 1) else [1.0, 1.0, 1.0, 1.0]
        outside = data_range is not None and not data_range[0] <= value <= data_range[1]
        if math.isnan(value) or outside or look[3] <= 0.0 or value in values:
            continue
        values.append(value)
        colors.extend(look)
        labels.append(names[i] if names is not None else
                      ("%s %s" % (array, _format(value))).strip())
    if not values:
        raise ValueError("MakeMeshFromView: the display draws no surface.")

    # The plugin's proxies as paraview.simple's functions (LoadPlugin adds them
    # to the caller's namespace only).
    proxies = {}
    simple._add_functions(proxies)
    contour = proxies["BlockLODContour"](Input=servermanager.OutputPort(source, port))
    # By property name, not by the labels paraview.simple derives names from.
    settings = [("SelectInputScalars", ["POINTS", array]), ("ContourValues", values),
                ("ComputeScalars", 1), ("AutoLOD", 1 if level is None else 0)]
    if level is not None:
        settings.append(("LOD", level))
    for name, value in settings:
        contour.SetPropertyWithName(name, value)
    mesh = proxies["IsosurfaceLabels"](Input=contour)
    mesh.SurfaceValues = values
    mesh.SurfaceColors = colors
    mesh.SurfaceNames = labels
    source_name = next((key[0] for key, proxy in simple.GetSources().items() if proxy == source), "")
    simple.RenameSource(("Mesh of %s" % source_name) if source_name else "Isosurface mesh", mesh)
    mesh.UpdatePipeline()
    if show and view is not None:
        shown = simple.Show(mesh, view)
        _color_by_surface(shown, labels, colors)
        simple.Hide(source, view)
        simple.Render(view)
    return mesh


def _color_by_surface(shown, labels, colors):
    """Colours the mesh's display by SurfaceIndex through a colour map of its own: categorical,
    one annotation (the name), one colour and one opacity per surface (opacity mapping enabled
    where one is below 1). ParaView's PLY writer maps colours through the display's colour map
    (Save Data: Enable Coloring, SurfaceIndex), so this map also writes each surface's colour
    (and opacity, with Enable Alpha) to a PLY file."""
    simple.ColorBy(shown, ("CELLS", "SurfaceIndex"), True)
    lut = simple.GetColorTransferFunction("SurfaceIndex", shown, True)
    lut.InterpretValuesAsCategories = 1
    annotations, indexed = [], []
    for i, name in enumerate(labels):
        annotations += [str(i), name]
        indexed += colors[4 * i:4 * i + 3]
    lut.Annotations = annotations
    lut.IndexedColors = indexed
    lut.IndexedOpacities = colors[3::4]
    lut.EnableOpacityMapping = 1 if min(colors[3::4]) < 1.0 else 0


def _make_mesh_for_panel(display_id, view_id):
    """The panel's Make Mesh button: MakeMeshFromView on proxies given by their global ids."""
    session = servermanager.ActiveConnection.Session

    def proxy(global_id):
        found = session.GetRemoteObject(global_id) if global_id else None
        return servermanager._getPyProxy(found) if found is not None else None

    return MakeMeshFromView(proxy(display_id), proxy(view_id))


class RefineAfterChange:
    """Answers an isovalue change of a Block LOD Contour at a coarse level first, then refines it
    to the level the user set (see the module's description; docs/blocklod.md, Answering an
    isovalue change coarse first).

    ``contour``: a BlockLODContour proxy; its AutoLOD, LOD and MemoryBudget as they are now give
    the refinement's level (the helper restores them after each first answer). ``view``: the
    view that shows it (default: the active view). ``frame_budget``: the seconds the first
    answer's extraction and frame may take together: the extraction as the filter's estimator
    predicts it for the new isovalues (its CurrentEstimatedSeconds: 0 for a cached surface; its
    cost model learns from the filter's updates), the frame as the Block LOD display's
    frame-time model predicts it for the level's estimated triangles (its
    BlockLODPredictedStillSeconds; 0 before the display has drawn a frame).

    ``change(values, newer=None)`` returns ``{"values", "first_level", "first_seconds",
    "level", "seconds", "aborted", "note", "first_note"}``: the level the first render drew and
    the seconds from the change to it, the level reached and the seconds to it (the first's when
    the first answer is already at the user's level; None when aborted), what the view shows
    now and what the first answer said (a coarse one says so). ``newer`` is polled at the
    refinement's progress events, which needs the filter in this process (a builtin session);
    in client/server it is not polled and the refinement runs to its end. ``refinements`` and
    ``refinements_aborted`` count the refinements begun and those a newer change stopped.
    """

    def __init__(self, contour, view=None, frame_budget=0.1):
        self.contour = contour
        self.view = view or simple.GetActiveView()
        self.frame_budget = float(frame_budget)
        self.auto_lod = int(contour.AutoLOD)
        self.lod = int(contour.LOD)
        self.refinements = 0
        self.refinements_aborted = 0
        self.last = None

    def _estimates(self):
        """The filter's estimated MB and extraction seconds per level for the isovalues set now
        (one information update for both: each computes the estimates anew), and the display's
        predicted still frame per level for them (-1 each where it has none: no Block LOD
        display, no frame drawn yet)."""
        self.contour.UpdatePropertyInformation()
        megabytes = [float(x) for x in self.contour.GetProperty("CurrentEstimatedMB")]
        seconds = [float(x) for x in self.contour.GetProperty("CurrentEstimatedSeconds")]
        drawing = [-1.0] * 4
        display = simple.GetDisplayProperties(self.contour, self.view)
        found = display.SMProxy.GetProperty("BlockLODPredictedStillSeconds") if display else None
        if found is not None:
            found.GetParent().UpdatePropertyInformation()
            drawing = [float(found.GetElement(i)) for i in range(4)]
        return megabytes, seconds, drawing

    def levels(self):
        """For the isovalues set now: (the refinement's level, the first answer's level, its
        predicted seconds). The refinement's: LOD, or with Auto LOD the finest level whose
        estimated surfaces fit the Memory Budget (the choice the filter makes; 0 when none does).
        The first answer's: the finest at or below it whose estimated extraction and predicted
        frame (the display's frame-time model, where it has a prediction) fit the frame budget
        together (level 0 when none does)."""
        megabytes, seconds, drawing = self._estimates()
        if min(seconds) < 0 or min(megabytes) < 0:
            return self.lod, self.lod, -1.0  # no estimate (no update yet): no coarse answer
        memory = self.lod
        if self.auto_lod:
            budget = float(self.contour.MemoryBudget)
            memory = next((l for l in range(3, 0, -1) if megabytes[l] <= budget), 0)
        total = [s + max(0.0, d) for s, d in zip(seconds, drawing)]
        first = next((l for l in range(memory, -1, -1) if total[l] <= self.frame_budget), 0)
        return memory, first, total[first]

    def change(self, values, newer=None):
        start = time.perf_counter()
        values = [float(v) for v in values]
        self.contour.Isosurfaces = values
        memory, first, predicted = self.levels()
        if first >= memory:
            self._restore()
        else:
            self.contour.AutoLOD = 0
            self.contour.LOD = first
        simple.Render(self.view)
        first_seconds = time.perf_counter() - start
        shown = self._chosen_level()
        result = {"values": values, "first_level": shown, "first_seconds": first_seconds,
                  "level": shown, "seconds": first_seconds, "aborted": False,
                  "predicted_seconds": predicted, "note": "", "first_note": ""}
        self.last = result
        if first >= memory:
            return result
        result["note"] = result["first_note"] = (
            "First answer: level %d (level %d's extraction is predicted over %g s); refining."
            % (shown, memory, self.frame_budget))
        # The refinement: the user's level, with the newer change polled at the filter's
        # progress events; a true answer sets AbortExecute, which the filter honours between
        # chunks of blocks and between surfaces.
        self.refinements += 1
        self._restore()
        found = self.contour.GetClientSideObject()
        stopped = []

        def poll(algorithm, event):
            if newer is not None and not stopped and newer():
                stopped.append(True)
                algorithm.SetAbortExecute(1)

        tag = found.AddObserver("ProgressEvent", poll) if found is not None else None
        try:
            self.contour.UpdatePipeline()
        finally:
            if tag is not None:
                found.RemoveObserver(tag)
        if stopped:
            found.SetAbortExecute(0)
            self.refinements_aborted += 1
            # The aborted update left the output empty: back to the level shown, so that any
            # render before the newer change's draws the first answer again (from the cache).
            self.contour.AutoLOD = 0
            self.contour.LOD = shown
            result.update(level=shown, seconds=None, aborted=True,
                          note="Level %d: its refinement was aborted by a newer change." % shown)
            return result
        simple.Render(self.view)
        result.update(level=self._chosen_level(), seconds=time.perf_counter() - start, note="")
        return result

    def _chosen_level(self):
        self.contour.UpdatePropertyInformation()
        return int(self.contour.GetProperty("ChosenLevel")[0])

    def _restore(self):
        self.contour.AutoLOD = self.auto_lod
        self.contour.LOD = self.lod


def RefineHistoPyramidChange(display, values, view=None):
    """Answers an isovalue change of a *HistoPyramid Isosurface* display at a coarse level first,
    then at full quality (issue 30; docs/blocklod.md, The first answer's frame counted).

    Sets ``display.IsosurfaceValues`` to ``values``, draws an interactive render (the mapper's
    interactive choice within its HistoPyramidInteractiveFrameBudget: a coarse volume level, a
    sample distance or a Block LOD level's triangles, predicted from the last values' active
    pairs; only the drawn level's pyramid is built), then the still render (the full volume,
    its pyramid built for the new values). With HistoPyramidInteractiveAdjust off both are the
    still frame. Returns ``{"values", "first_level", "first_sample_distance", "first_seconds",
    "level", "seconds"}``: what the first render drew and the seconds from the change to it, the
    still render's level and the seconds to it.
    """
    view = view or simple.GetActiveView()
    start = time.perf_counter()
    display.IsosurfaceValues = [float(v) for v in values]
    view.InteractiveRender()
    first_seconds = time.perf_counter() - start

    def drawn():
        display.UpdatePropertyInformation()
        return (int(display.GetProperty("HistoPyramidLastLevel")[0]),
                float(display.GetProperty("HistoPyramidLastSampleDistance")[0]))

    first_level, first_distance = drawn()
    view.StillRender()
    seconds = time.perf_counter() - start
    level, _ = drawn()
    return {"values": [float(v) for v in values], "first_level": first_level,
            "first_sample_distance": first_distance, "first_seconds": first_seconds,
            "level": level, "seconds": seconds}
