"""Write a representation's help page from the plugin's ServerManager XML.

  python3 representation_help.py XML PROXY_NAME OUTPUT.html

ParaView 5.11 makes help pages (paraview_add_plugin's XML_DOCUMENTATION) for
sources, filters and readers only, so a representation, however central, has
none and Help's search cannot find it. This page is built from the same XML:
the representation proxy's <Documentation> (short help, then its paragraphs,
split at blank lines), and every property of the proxy with its
<Documentation>, default and where the display shows it: the name and label
it is exposed under by the extension that adds the representation type (a
<SubProxy> naming the proxy, its <ExposedProperties>), the property group
that holds it, or the display's property it is shared with. Nothing is
written here that the XML does not say, so each fact is stated once, in the
XML; the page lands next to the filters' pages in the plugin's .qch
(Plugin/CMakeLists.txt hands its folder to paraview_add_plugin).
"""
import html
import re
import sys
import xml.etree.ElementTree as ET

PROPERTY_TAGS = {"IntVectorProperty", "DoubleVectorProperty", "IdTypeVectorProperty",
                 "StringVectorProperty", "ProxyProperty", "InputProperty"}


def pretty_label(name):
    """The label ParaView gives a property without one (vtkSMProperty::
    CreateNewPrettyLabel): words split where the case changes."""
    return re.sub(r"(?<=[a-z])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])", " ", name)


def paragraphs(text):
    """The documentation's paragraphs (blank lines in the XML), whitespace folded."""
    return [" ".join(block.split()) for block in re.split(r"\n\s*\n", (text or "").strip())
            if block.strip()]


def documentation(element):
    doc = element.find("Documentation")
    if doc is None:
        return "", []
    return " ".join((doc.get("short_help") or "").split()), paragraphs(doc.text)


def exposures(root, proxy_name):
    """Where the extensions adding this representation show its properties:
    {name: (exposed name, label, group label, panel_visibility)}; and the
    representation type's name in the display's Representation list."""
    shown, type_name = {}, None
    for extension in root.iter("Extension"):
        for rtype in extension.iter("RepresentationType"):
            if rtype.get("subproxy") == proxy_name:
                type_name = rtype.get("text")
        for sub in extension.findall("SubProxy"):
            proxy = sub.find("Proxy")
            if proxy is None or proxy.get("proxyname") != proxy_name:
                continue
            exposed = sub.find("ExposedProperties")
            if exposed is None:
                continue
            for item in exposed:
                group = item.get("label") if item.tag == "PropertyGroup" else None
                group_visibility = item.get("panel_visibility")
                for prop in ([item] if item.tag == "Property" else item.findall("Property")):
                    shown[prop.get("name")] = (prop.get("exposed_name") or prop.get("name"),
                                               prop.get("label"), group,
                                               prop.get("panel_visibility") or group_visibility)
        # Groups of the display itself that name an exposed property (a widget
        # editing it, e.g. a plane widget for a plane's origin and normal).
        for group in extension.findall("PropertyGroup"):
            for prop in group.findall("Property"):
                for name, (exposed_name, label, where, visibility) in list(shown.items()):
                    if prop.get("name") == exposed_name and where is None:
                        shown[name] = (exposed_name, label, group.get("label"), visibility)
    return shown, type_name


def main(xml_path, proxy_name, output):
    root = ET.parse(xml_path).getroot()
    proxy = next((p for p in root.iter() if p.get("name") == proxy_name and
                  p.tag.endswith("Proxy") and p.get("class")), None)
    if proxy is None:
        sys.exit("representation_help.py: no proxy %s in %s" % (proxy_name, xml_path))
    short, long_paragraphs = documentation(proxy)
    shown, type_name = exposures(root, proxy_name)
    title = type_name or pretty_label(proxy_name)

    rows = []
    for prop in proxy:
        if prop.tag not in PROPERTY_TAGS:
            continue
        name = prop.get("name")
        prop_short, prop_paragraphs = documentation(prop)
        text = " ".join([prop_short] + prop_paragraphs).strip()
        exposed_name, label, group, visibility = shown.get(name, (name, None, None, None))
        visibility = visibility or prop.get("panel_visibility")
        where = []
        if group:
            where.append("panel group <i>%s</i>" % html.escape(group))
        if name not in shown:
            where.append("shared with the display's property of that name")
        if visibility in ("advanced", "never"):
            where.append("advanced" if visibility == "advanced" else "not in the panel")
        default = prop.get("default_values") or ""
        if prop.get("information_only") == "1":
            where.append("read-only")
            default = ""  # what the last frame did, not a setting
        rows.append(
            "<tr><th>%s</th><td><code>%s</code></td><td>%s</td><td>%s</td><td>%s</td></tr>" % (
                html.escape(label or pretty_label(name)), html.escape(exposed_name),
                html.escape(text), html.escape(default),
                "; ".join(where)))

    body = ["<h2>%s (%s)</h2>" % (html.escape(title), html.escape(proxy_name)),
            "<p>A representation type of the MedicalIsosurfaces plugin: choose <i>%s</i> in a "
            "display's <i>Representation</i> list.</p>" % html.escape(title)]
    if short:
        body.append("<i><p>%s</p></i>" % html.escape(short))
    body += ["<p>%s</p>" % html.escape(p) for p in long_paragraphs]
    body.append("<h3>Properties</h3>")
    body.append("<p>Name: the display's property in Python "
                "(<code>display.Name = value</code>) and <code>GetProperty</code>.</p>")
    body.append('<table width="97%" border="2px"><tr bgcolor="#9acd32"><th>Property</th>'
                '<th>Name</th><th width="55%">Description</th><th>Default(s)</th>'
                '<th>Shown</th></tr>')
    body += rows
    body.append("</table>")
    page = ("<html>\n<head>\n<title>%s</title>\n"
            '<meta name="proxy_name" contents="representations.%s"/>\n</head>\n<body>\n%s\n'
            "</body>\n</html>\n" % (html.escape(title), proxy_name, "\n".join(body)))
    with open(output, "w", encoding="utf-8") as out:
        out.write(page)


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:])
