"""Plain python3 test: the plugin's Qt help collection holds its pages (no GUI, no X).

    python3 TestPluginHelpCollection.py QCH XML

QCH is the built help collection (build/Plugin/paraview_help/MedicalIsosurfaces.qch),
XML the plugin's ServerManager XML (Plugin/MedicalIsosurfaces.xml). Checked
(qthelp.check_collection): the filter's and the source's pages, and the
HistoPyramid Isosurface representation's page, which ParaView does not make
(Plugin/representation_help.py does): its title, "HistoPyramid", the paper, the
XML's paragraph on when it falls back to the CPU, and every property of the
representation with its name, label and documentation from the XML, read from
the collection's compressed file data as Help reads it.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)
import qthelp  # noqa: E402  (Testing/Python/qthelp.py)

if len(sys.argv) != 3:
    sys.exit(__doc__)
qch, xml = sys.argv[1:]
check = Checks()
if check(os.path.isfile(qch), "the help collection %s exists" % qch):
    names = qthelp.check_collection(check, qch, xml)
    print("%s: %d files: %s" % (qch, len(names), ", ".join(sorted(n for n in names if n))))
check.finish("TestPluginHelpCollection: the representation's help page is in the collection")
