"""Shared pieces of the client/server tests (run by Testing/Scripts/client-server.sh).

- parse_args(): the arguments client-server.sh passes (--port, --server-pid,
  --plugin, --relay-control, ...), plus --representation and the test's own.
- Checks: collects failures, prints "FAILED: ..." (ctest's fail pattern) and
  sets the exit status.
- RelayCounter: bytes client->server and server->client per named step, read
  from the byte relay (Testing/Scripts/byte_relay.py), and the per-step table.
- connect() and load_plugin(): the session and the plugin's proxies, the
  plugin either loaded from the client (LoadPlugin(path, remote=True)) or
  found by pvserver on PV_PLUGIN_PATH.
- surface_representation(): where a test picks the representation that draws
  an isosurface. "Surface" draws BlockLODContour's output; the GPU mapper's
  representation ("HistoPyramid Isosurface", issue 4) draws the volume itself
  and is passed with --representation once it exists.
- image_coverage(): the fraction of a view's pixels that differ from the
  background, from the image the client receives.
"""
import argparse
import os
import socket
import sys
import time

import checks  # Testing/Python/checks.py

from paraview import servermanager
import paraview.simple as simple

# Representations the tests know how to drive. The GPU representation is shown
# on the volume (not on a contour filter's output) and takes its isovalue from
# its own property; tests parameterised on the representation use these.
SURFACE = "Surface"
HISTOPYRAMID = "HistoPyramid Isosurface"


def parse_args(description, extra=None):
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--host", default="localhost")
    parser.add_argument("--port", type=int, required=True, help="the port the client connects to")
    parser.add_argument("--server-port", type=int, default=0)
    parser.add_argument("--server-pid", type=int, default=0)
    parser.add_argument("--server-log", default="")
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--relay-control", default="", help="byte relay control socket")
    parser.add_argument("--plugin-on-server-path", action="store_true",
                        help="pvserver was started with PV_PLUGIN_PATH (no remote LoadPlugin)")
    parser.add_argument("--representation", default=SURFACE,
                        help="representation that draws the isosurface (%s or %s)"
                        % (SURFACE, HISTOPYRAMID))
    if extra:
        extra(parser)
    return parser.parse_args()


class Checks(checks.Checks):
    def finish(self, passed_message):
        # Disconnect first: a client that just exits leaves pvserver logging a
        # socket error.
        if servermanager.ActiveConnection is not None:
            simple.Disconnect()
        super().finish(passed_message, exit=os._exit)


class RelayCounter:
    """Bytes through the relay, per step: step(name) after each client action."""

    def __init__(self, control_path):
        self.path = control_path
        self.rows = []
        self.last = self.totals()

    def totals(self):
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
            s.settimeout(10)
            s.connect(self.path)
            s.sendall(b"totals\n")
            data = b""
            while not data.endswith(b"\n"):
                chunk = s.recv(256)
                if not chunk:
                    break
                data += chunk
        c2s, s2c, connections = (int(x) for x in data.split())
        return c2s, s2c, connections

    def step(self, name, settle=0.2):
        """Bytes since the previous step. `settle` seconds let asynchronous
        messages (progress, log forwarding) that belong to the step arrive."""
        if settle:
            time.sleep(settle)
        now = self.totals()
        row = (name, now[0] - self.last[0], now[1] - self.last[1])
        self.last = now
        self.rows.append(row)
        return row[1], row[2]

    def table(self, title):
        lines = [title, "| step | client->server B | server->client B |", "|---|---:|---:|"]
        for name, c2s, s2c in self.rows:
            lines.append("| %s | %d | %d |" % (name, c2s, s2c))
        return "\n".join(lines)


def connect(args, timeout=30):
    connection = simple.Connect(args.host, args.port, timeout=timeout)
    if connection is None or not servermanager.ActiveConnection.IsRemote():
        print("FAILED: could not connect to %s:%d" % (args.host, args.port))
        sys.stdout.flush()
        os._exit(1)
    return connection


def load_plugin(args):
    """The plugin's proxy functions (MedicalPhantom, BlockLODContour) in a dict."""
    ns = {"__name__": "medical_isosurfaces_proxies"}  # not empty: LoadPlugin treats {} as "no namespace"
    if args.plugin_on_server_path:
        # pvserver loaded it from PV_PLUGIN_PATH at start-up: only the client's
        # proxy functions need refreshing.
        simple._add_functions(ns)
    else:
        simple.LoadPlugin(args.plugin, remote=True, ns=ns)
    if getattr(args, "representation", SURFACE) != SURFACE:
        # A representation has a client-side object too (ParaView creates it
        # on every process of the view): the client needs the library as well.
        simple.LoadPlugin(args.plugin, remote=False, ns=ns)
    return ns


def plugin_mapped_here(plugin):
    with open("/proc/self/maps") as maps:
        return any(os.path.basename(plugin) in line for line in maps)


def surface_representation(view, contour, volume, name, isovalue):
    """Shows an isosurface with the named representation and returns it."""
    if name == SURFACE:
        display = simple.Show(contour, view)
        display.Representation = SURFACE
        display.ColorArrayName = ["POINTS", ""]
        return display
    # The GPU representation draws the volume's isosurface itself, opaque,
    # coloured by the volume's HU array.
    display = simple.Show(volume, view)
    display.SetRepresentationType(name)
    simple.ColorBy(display, ("POINTS", "HU"))
    simple.GetOpacityTransferFunction("HU").Points = [-3000.0, 1.0, 0.5, 0.0, 3000.0, 1.0, 0.5, 0.0]
    display.IsosurfaceValues = [isovalue]
    return display


def set_isovalue(display, contour, name, isovalue):
    if name == SURFACE:
        contour.Isosurfaces = [isovalue]
    else:
        display.IsosurfaceValues = [isovalue]


def image_coverage(view):
    """Fraction of pixels unlike the background in the image the client gets."""
    image = view.SMProxy.CaptureImage(1) if hasattr(view.SMProxy, "CaptureImage") else view.SMProxy.CaptureWindow(1)
    scalars = image.GetPointData().GetScalars()
    n = scalars.GetNumberOfTuples()
    components = scalars.GetNumberOfComponents()
    corner = [scalars.GetComponent(0, c) for c in range(min(components, 3))]
    differ = 0
    step = max(1, n // 20000)
    sampled = 0
    for i in range(0, n, step):
        sampled += 1
        if any(abs(scalars.GetComponent(i, c) - corner[c]) > 8 for c in range(len(corner))):
            differ += 1
    dims = image.GetDimensions()
    return differ / float(max(sampled, 1)), (dims[0], dims[1])
