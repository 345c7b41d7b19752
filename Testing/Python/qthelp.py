"""The plugin's Qt help collection (.qch), read as the tests check it (plain python3).

A .qch is an SQLite database (Qt's qhelpgenerator writes it, QHelpDBReader reads
it): FileNameTable names each file (Name, FileId, Title), FileDataTable holds
its contents under that id, compressed as Qt's qCompress does: a 4-byte
big-endian length of the uncompressed data, then a zlib stream.

    files = read_files(qch)                       # {name: bytes}
    check_collection(check, qch, xml)             # every check of the help pages

check_collection() checks what Help must find: the filter's and the source's
pages (ParaView's XML_DOCUMENTATION), and the HistoPyramid Isosurface
representation's page (Plugin/representation_help.py) holding, as text,
"HistoPyramid", the paper's title, the representation's paragraph on when it
falls back to the CPU, and every property of the representation proxy in the
ServerManager XML: the name the display shows it under, its label where the
XML gives one, and its documentation.
"""
import html.parser
import re
import sqlite3
import xml.etree.ElementTree as ET
import zlib

REPRESENTATION = "HistoPyramidIsosurfaceRepresentation"
REPRESENTATION_PAGE = "representations.%s.html" % REPRESENTATION
PAPER = "Hardware Accelerated Medical Data Visualisation on the Web"
PROPERTY_TAGS = {"IntVectorProperty", "DoubleVectorProperty", "IdTypeVectorProperty",
                 "StringVectorProperty", "ProxyProperty", "InputProperty"}


def read_files(qch):
    """{name: contents} of every file in the collection (contents None when unreadable)."""
    files = {}
    db = sqlite3.connect(qch)
    try:
        for name, data in db.execute("SELECT n.Name, d.Data FROM FileNameTable n "
                                     "LEFT JOIN FileDataTable d ON d.Id = n.FileId"):
            contents = None
            if data is not None and len(data) > 4:
                length = int.from_bytes(data[:4], "big")
                try:
                    contents = zlib.decompress(data[4:])
                except zlib.error:
                    contents = None
                if contents is not None and len(contents) != length:
                    contents = None
            files[name] = contents
    finally:
        db.close()
    return files


class _Text(html.parser.HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.parts = []

    def handle_starttag(self, tag, attrs):
        self.parts.append(" ")

    def handle_endtag(self, tag):
        self.parts.append(" ")

    def handle_data(self, data):
        self.parts.append(data)


def page_text(contents):
    """A page's text as a reader sees it: tags dropped, entities decoded, spaces folded."""
    parser = _Text()
    parser.feed(contents.decode("utf-8"))
    return " ".join("".join(parser.parts).split())


def _fold(text):
    return " ".join((text or "").split())


def representation_facts(xml):
    """From the XML: the representation's paragraph on the CPU fallback, and per
    property (name on the display, label or None, documentation)."""
    root = ET.parse(xml).getroot()
    proxy = next(p for p in root.iter() if p.get("name") == REPRESENTATION and p.get("class"))
    long_help = proxy.find("Documentation").text or ""
    blocks = [_fold(b) for b in re.split(r"\n\s*\n", long_help)]
    fallback = [b for b in blocks if "falls back to the CPU" in b]
    exposed = {}
    for sub in root.iter("SubProxy"):
        target = sub.find("Proxy")
        if target is None or target.get("proxyname") != REPRESENTATION:
            continue
        for prop in sub.iter("Property"):
            if prop.get("exposed_name"):
                exposed[prop.get("name")] = (prop.get("exposed_name"), prop.get("label"))
    properties = []
    for prop in proxy:
        if prop.tag in PROPERTY_TAGS:
            name, label = exposed.get(prop.get("name"), (prop.get("name"), None))
            doc = prop.find("Documentation")
            properties.append((name, label, _fold(doc.text if doc is not None else "")))
    return fallback, properties


def check_collection(check, qch, xml):
    """Every check of the collection's pages; returns the names of its files."""
    try:
        files = read_files(qch)
    except sqlite3.Error as error:
        check(False, "%s is a Qt help collection (%s)" % (qch, error))
        return set()
    names = set(files)
    check({"filters.BlockLODContour.html", "sources.MedicalPhantom.html"} <= names,
          "help: the collection holds the filter's and the source's pages (%s)" % sorted(names))
    if not check(REPRESENTATION_PAGE in names,
                 "help: the collection holds the representation's page %s" % REPRESENTATION_PAGE):
        return names
    contents = files[REPRESENTATION_PAGE]
    if not check(contents is not None, "help: %s's data decompresses" % REPRESENTATION_PAGE):
        return names
    text = page_text(contents)
    check("<title>HistoPyramid Isosurface</title>" in contents.decode("utf-8"),
          "help: the page's title (its entry in Help's contents) is HistoPyramid Isosurface")
    check("HistoPyramid" in text, "help: the page's text says HistoPyramid")
    check(PAPER in text, "help: the page names the paper (%s)" % PAPER)
    fallback, properties = representation_facts(xml)
    check(len(fallback) == 1, "the XML's representation documentation has one paragraph "
          "on when it falls back to the CPU (%d)" % len(fallback))
    for paragraph in fallback:
        check(paragraph in text, "help: the page holds the fallback paragraph: %s" % paragraph)
    check(len(properties) >= 20, "the XML gives the representation's properties (%d)"
          % len(properties))
    for name, label, doc in properties:
        check(name in text, "help: the page names property %s" % name)
        if label:
            check(label in text, "help: the page gives %s's label %r" % (name, label))
        check(len(doc) > 20 and doc in text,
              "help: the page holds %s's documentation (%r)" % (name, doc[:60]))
    return names
