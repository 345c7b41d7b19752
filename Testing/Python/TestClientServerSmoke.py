"""Client/server smoke test (run by Testing/Scripts/client-server.sh).

The client connects to a pvserver in a loopback-only namespace, loads the plugin
on the server only (LoadPlugin(..., remote=True)), creates MedicalPhantom there
and reads its data information. It proves the source ran in the server process:
the data's ProducerProcessId is the pvserver's process id, not the client's, and
the plugin library is not even mapped into the client process.
"""
import argparse
import os
import sys

from paraview.simple import *  # noqa: F401,F403

parser = argparse.ArgumentParser()
parser.add_argument("--host", default="localhost")
parser.add_argument("--port", type=int, required=True)
parser.add_argument("--server-pid", type=int, required=True)
parser.add_argument("--plugin", required=True)
args, _ = parser.parse_known_args()  # client-server.sh also passes relay arguments

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)

check = Checks()


def plugin_mapped_here():
    with open("/proc/self/maps") as maps:
        return any(os.path.basename(args.plugin) in line for line in maps)


connection = Connect(args.host, args.port, timeout=30)
if connection is None:
    print("FAILED: could not connect to %s:%d" % (args.host, args.port))
    sys.exit(1)
check(servermanager.ActiveConnection.IsRemote(), "the connection is remote")

LoadPlugin(args.plugin, remote=True, ns=globals())
check("MedicalPhantom" in globals(), "MedicalPhantom is available after a remote LoadPlugin")
check(not plugin_mapped_here(), "the plugin library is not loaded in the client process")

dims = [40, 36, 30]
phantom = MedicalPhantom(Dimensions=dims, Spacing=[2.0, 2.0, 2.5])
phantom.UpdatePipeline()
info = phantom.GetDataInformation()
check(tuple(info.GetExtent()) == (0, 39, 0, 35, 0, 29), "extent %s" % (info.GetExtent(),))
check(info.GetNumberOfPoints() == dims[0] * dims[1] * dims[2], "point count")
hu = phantom.PointData["HU"]
check(hu is not None and hu.GetDataType() == 4, "HU array is int16 on the client's view")
producer = phantom.FieldData["ProducerProcessId"]
producer_pid = int(producer.GetRange()[0]) if producer is not None else -1
check(producer_pid == args.server_pid,
      "data produced by pvserver pid %d (got %d)" % (args.server_pid, producer_pid))
check(producer_pid != os.getpid(), "data not produced by the client (pid %d)" % os.getpid())
print("client pid %d, server pid %d, producer pid %d, extent %s, HU range %s"
      % (os.getpid(), args.server_pid, producer_pid, info.GetExtent(), hu.GetRange()))

Disconnect()
check.finish("client/server smoke: all checks passed")
