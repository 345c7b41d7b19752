"""The web server's WebSocket messages, validated against one declarative table (docs/web.md).

    request = parse_message(text, datasets)   # a dict with the checked values, or BadRequest

MESSAGES names each operation's fields and STEPS each surface step's parameters, with a checker
per field (its type, its range, whether it may be left out). A message is checked in a fixed
order, so every fault has one answer: its size, JSON, an object, "id", "op", unknown fields, missing
fields, then each field in the table's order; the error text names the field and the fault
(e.g. "steps[0].smooth.iterations: 0 is outside 1-500").
"""
import json
import math
from dataclasses import dataclass
from typing import Callable

MAX_MESSAGE = 64 * 1024        # a request on the WebSocket
MAX_STEPS = 8


class BadRequest(Exception):
    """A message the server refuses; the text names what is wrong."""

    def __init__(self, text, ident=None):
        super().__init__(text)
        self.ident = ident


def _short(value):
    text = json.dumps(value) if not isinstance(value, str) else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


# ------------------------------------------------------------------------------ field checkers
# Each takes (value, where, context) and returns the checked value or raises BadRequest; context
# holds the server's datasets and the fields already checked (the isovalue needs the dataset).
def number(lo=None, hi=None, above=None):
    def check(value, where, context=None):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise BadRequest("%s: not a number (%s)" % (where, _short(value)))
        value = float(value)
        if not math.isfinite(value):
            raise BadRequest("%s: not a finite number" % where)
        if (lo is not None and value < lo) or (hi is not None and value > hi):
            raise BadRequest("%s: %g is outside %g-%g" % (where, value, lo, hi))
        if above is not None and not value > above:
            raise BadRequest("%s: %g is not above %g" % (where, value, above))
        return value
    return check


def integer(lo, hi):
    def check(value, where, context=None):
        if isinstance(value, bool) or not isinstance(value, int):
            raise BadRequest("%s: not an integer (%s)" % (where, _short(value)))
        if not lo <= value <= hi:
            raise BadRequest("%s: %d is outside %d-%d" % (where, value, lo, hi))
        return value
    return check


def vector(nonzero=False):
    def check(value, where, context=None):
        if not isinstance(value, list) or len(value) != 3:
            raise BadRequest("%s: three numbers" % where)
        value = [number()(v, where) for v in value]
        if nonzero and math.sqrt(sum(c * c for c in value)) < 1e-12:
            raise BadRequest("%s: the zero vector" % where)
        return value
    return check


def boolean(value, where, context=None):
    if not isinstance(value, bool):
        raise BadRequest("%s: true or false (%s)" % (where, _short(value)))
    return value


def dataset(value, where, context):
    datasets = context["datasets"]
    found = datasets.get(value) if isinstance(value, str) else None
    if found is None:
        raise BadRequest("%s: no dataset %s (this server has %s)"
                         % (where, _short(value), ", ".join(sorted(datasets))))
    return found


def isovalue(value, where, context):
    value = number()(value, where)
    lo, hi = context["dataset"].range
    if not lo <= value <= hi:
        raise BadRequest("%s: %g is outside the data range %g..%g" % (where, value, lo, hi))
    return value


def steps(value, where, context):
    if not isinstance(value, list) or len(value) > MAX_STEPS:
        raise BadRequest("%s: a list of at most %d operations" % (where, MAX_STEPS))
    return [_step(s, "%s[%d]" % (where, i)) for i, s in enumerate(value)]


def export(value, where, context):
    options = _fields(value, where, EXPORT, {}, prefix=where + ".")
    return {key: options.get(key, spec.default) for key, spec in EXPORT.items()}


@dataclass(frozen=True)
class Field:
    check: Callable
    required: bool = True
    default: object = None  # what a field left out means (optional fields)


# ------------------------------------------------------------------------------ the table
# Level k of a volume samples the points at multiples of LEVEL_STRIDES[k] along each axis: the
# strides of the C++ BlockLOD core, mediso::LevelStride(k) = BlockCells >> k = 8 >> k
# (Filters/Core/BlockLOD.h), which TestWebServerLevels checks against BlockLODContour at each
# level and TestWebPage_budget against the strides the WebAssembly module reports. The one
# difference: the C++'s coarse copy (MakeCoarseCopy) also takes the last point of
# an axis whose length minus one is not a multiple of the stride; the levels sent to the page
# leave that partial layer out (docs/web.md, "The server").
LEVEL_STRIDES = (8, 4, 2, 1)
LEVELS = len(LEVEL_STRIDES)

# op -> its fields besides "op" and "id", checked in this order.
MESSAGES = {
    "surface": {"dataset": Field(dataset), "isovalue": Field(isovalue),
                "level": Field(integer(0, LEVELS - 1)), "steps": Field(steps, required=False),
                "export": Field(export, required=False)},
    "cancel": {},
}

# A step is {name: parameters}; the worker maps each name to its VTK filter.
STEPS = {
    "smooth": {"iterations": Field(integer(1, 500)),
               "relaxation": Field(number(0, 1), required=False)},
    "fillHoles": {"size": Field(number(above=0))},
    "clip": {"origin": Field(vector()), "normal": Field(vector(nonzero=True))},
    "decimate": {"reduction": Field(number(0, 0.99))},
}


# The export options, applied after the steps (serve_operations.Worker.export; docs/web.md,
# "Export"). Cleaning is on unless asked off: an STL reader (a slicer, a mesh checker) merges
# corners at the same position, so unmerged duplicates and zero-length edges would otherwise be
# found there as degenerate triangles and spurious edges.
EXPORT = {
    "clean": Field(boolean, required=False, default=True),  # merge points at the same position,
    # drop triangles left with fewer than three corners and all but one of triangles on the same
    # three corners
    "largestComponent": Field(boolean, required=False, default=False),  # keep the largest
    # connected piece (by triangles), drop the rest
    "cap": Field(boolean, required=False, default=False),  # close the surface where the
    # volume's box cuts it: contoured with one more sample of the data's minimum around the volume
}

# The mesh report of a result, the "report" of the done message: each field stated once, as the
# worker computes it with VTK on the written mesh (serve_operations.mesh_report), the page shows
# it and TestWebServerExport counts it again with numpy on the STL. Corners at the same position
# are one point, as an STL reader sees them; edges and pieces are those of the triangles with three
# distinct corners.
REPORT = {
    "triangles": "triangles in the files",
    "points": "distinct corner positions",
    "components": "connected pieces (triangles sharing a corner), vtkPolyDataConnectivityFilter",
    "boundaryEdges": "edges of one triangle only, vtkFeatureEdges (0: no hole, no open cut)",
    "nonManifoldEdges": "edges of three or more triangles, vtkFeatureEdges",
    "degenerateTriangles": "triangles with two or three corners at the same position",
    "duplicateTriangles": "triangles on the same three corners as an earlier one (either "
                          "orientation)",
    "watertight": "no boundary and no non-manifold edge: every edge between exactly two triangles",
}


def _fields(obj, where, table, context, prefix="", known=()):
    """obj's fields checked against the table: unknown, then missing, then each value (named
    prefix + its key in errors)."""
    if not isinstance(obj, dict):
        raise BadRequest("%s: an object" % where)
    for key in obj:
        if key not in table and key not in known:
            raise BadRequest("%s: unknown field %s" % (where, _short(key)))
    for key in tuple(known) + tuple(k for k, f in table.items() if f.required):
        if key not in obj:
            raise BadRequest("%s: %s is missing" % (where, key))
    out = {}
    for key, spec in table.items():
        if key in obj:
            out[key] = context[key] = spec.check(obj[key], prefix + key, context)
    return out


def _step(step, where):
    if not isinstance(step, dict) or len(step) != 1:
        raise BadRequest("%s: one operation, e.g. {\"smooth\": {...}}" % where)
    (name, params), = step.items()
    if name not in STEPS:
        raise BadRequest("%s: unknown operation %s (%s)" % (where, _short(name), ", ".join(STEPS)))
    where = "%s.%s" % (where, name)
    return {name: _fields(params, where, STEPS[name], {}, prefix=where + ".")}


def parse_message(text, datasets):
    """A validated request from a WebSocket text frame; BadRequest otherwise."""
    size = len(text.encode("utf-8"))
    if size > MAX_MESSAGE:
        raise BadRequest("message too long: %d bytes (at most %d)" % (size, MAX_MESSAGE))
    try:
        message = json.loads(text)  # NaN and Infinity parse, and are refused as not finite
    except (ValueError, RecursionError) as e:
        raise BadRequest("not JSON: %s" % str(e)[:80])
    if not isinstance(message, dict):
        raise BadRequest("a message is a JSON object")
    ident = message.get("id")
    if isinstance(ident, bool) or not isinstance(ident, int) or abs(ident) > 2 ** 53:
        raise BadRequest("id: an integer (%s)" % _short(ident))
    op = message.get("op")
    if op not in MESSAGES:
        raise BadRequest("op: unknown operation %s (%s)" % (_short(op), ", ".join(MESSAGES)),
                         ident)
    try:
        fields = _fields(message, op, MESSAGES[op], {"datasets": datasets}, known=("op", "id"))
    except BadRequest as e:
        e.ident = ident
        raise
    if op == "surface":
        fields.setdefault("steps", [])
        fields.setdefault("export", export({}, "export", {}))
    return dict(fields, op=op, id=ident)
