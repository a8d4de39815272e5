# Sphinx configuration of the API reference (scripts/docs.sh builds it; Debian's Sphinx 5.3 and
# breathe 4.34). The script passes where the built Python module and Doxygen's XML are:
#   PLATE_PYTHON_DIR   BUILD/python (the package `plate` with its compiled half)
#   PLATE_DOXYGEN_XML  Doxygen's XML of the public C++ headers (Doxyfile beside this file)
import os
import re
import sys
from xml.etree import ElementTree

from breathe.directives.content_block import DoxygenGroupDirective
from breathe.renderer.sphinxrenderer import SphinxRenderer
from docutils import nodes
from sphinx import addnodes
from sphinx.util import logging

sys.path.insert(0, os.environ["PLATE_PYTHON_DIR"])
import plate  # noqa: E402  (the module the Python pages document; an import error stops the build)

project = "plate"
author = "The plate developers"   # (CITATION.cff)
copyright = "2026, " + author
version = release = plate.__version__

extensions = ["sphinx.ext.autodoc", "breathe"]
exclude_patterns = []
root_doc = "index"
default_role = "literal"   # (`name` in docstrings and comments is code)
nitpicky = True            # (-n: every cross-reference must resolve; the ones that cannot are listed below)
highlight_language = "none"
smartquotes_action = "D"   # (-- an en dash, --- an em dash; quotes stay as typed: docstrings' dicts are code)

html_theme = "alabaster"
html_theme_options = {"page_width": "1200px", "sidebar_width": "260px", "fixed_sidebar": True,
                      "description": "sliding manipulation on a vibrating 6-DoF plate"}
html_sidebars = {"**": ["about.html", "navigation.html", "searchbox.html"]}
html_static_path = ["_static"]   # (custom.css, which alabaster loads)
html_show_sourcelink = False

# --- Python: the module `plate` (pybind11). Its classes live in plate._plate and are re-exported by
# plate; signatures and docstrings name them as plate.X, which is where these pages put them.
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
autodoc_default_options = {"members": True, "undoc-members": True}
autoclass_content = "both"   # (a class's docstring and its constructor's, whose signature pybind11 writes)


def _public_names(app, what, name, obj, options, signature, return_annotation):
    if signature:
        signature = signature.replace("plate._plate.", "plate.")
        signature = re.sub(r"^\(self(: [\w.]+)?(, )?", "(", signature)   # (pybind11 names self in methods)
    if return_annotation:
        return_annotation = return_annotation.replace("plate._plate.", "plate.")
    return signature, return_annotation


# The docstrings are plain text, `name` for code (the module's own docstring aside, which is
# reStructuredText): outside backticks, the characters reStructuredText would read as markup (|x|
# a substitution, *x emphasis, x_ a link, a backslash an escape) are escaped.
_RST_MARKUP = re.compile(r"([\\|*])|(?<=\w)_(?=\W|$)")


def _plain_text(line):
    parts = line.split("`")
    if len(parts) % 2 == 0:
        parts = [line]
    for i in range(0, len(parts), 2):
        parts[i] = _RST_MARKUP.sub(lambda m: "\\" + m.group(0), parts[i])
    return "`".join(parts)


def _public_docstring(app, what, name, obj, options, lines):
    for i, line in enumerate(lines):
        line = line.replace("plate._plate.", "plate.")
        lines[i] = line if what == "module" else _plain_text(line)


class HeaderDescription(DoxygenGroupDirective):
    """`.. header-description:: field_hpp`: the comment at the top of a header (its group's
    description, doxygen_filter.py), as paragraphs -- without breathe's "group field_hpp" line."""

    def run(self):
        self.options["desc-only"] = None
        for node in super().run():
            if isinstance(node, nodes.Element):
                for content in node.traverse(addnodes.desc_content):
                    return list(content.children)
        return []


def _every_public_name_documented(app, env):
    """A name in plate.__all__ that python.rst does not document is a warning (an error under -W)."""
    documented = env.get_domain("py").objects
    for name in plate.__all__:
        if "plate." + name not in documented:
            logging.getLogger(__name__).warning("plate.%s (in plate.__all__) is not documented: add it to python.rst", name)


def setup(app):
    app.connect("env-check-consistency", _every_public_name_documented)
    app.connect("autodoc-process-signature", _public_names)
    app.connect("autodoc-process-docstring", _public_docstring)
    app.add_directive("header-description", HeaderDescription)


# Names from outside the project: not documented here, so not cross-referenced (numpy, Eigen, the
# standard library, nlohmann::json).
nitpick_ignore_regex = [
    ("py:class", r"numpy\..*"),
    ("py:class", r"(Path|os\.PathLike|Callable|Any)"),
    ("cpp:identifier", r"(std|Eigen|nlohmann|ceres)(::.*)?"),
    ("cpp:identifier", r"(Vec[236]|Mat[36])::.*"),   # (Eigen's members of the aliases)
    ("cpp:identifier", r"(detail|gen)(::.*)?"),   # (implementation and generated kernels, not documented)
    ("cpp:identifier", r"plate(::sweep|::proofs)?"),   # (the namespaces: every page is in one)
    ("cpp:identifier", r"HUGE_VAL"),
    ("py:class", r"pybind11_builtins\..*"),
]

# --- C++: Doxygen's XML of the public headers.
breathe_projects = {"plate": os.environ["PLATE_DOXYGEN_XML"]}


# Each header is a Doxygen group (doxygen_filter.py), shown by doxygengroup. breathe names a group's
# free functions, enums, typedefs and variables without their namespace (it takes the namespace from
# a namespace or file compound, and a group is neither), so `compute_field` would be declared at
# global scope and its `const Scene&` would not resolve. The namespace of each group's members, from
# the XML, is put back here.
def _group_namespaces(xml_dir):
    found = {}
    for name in os.listdir(xml_dir):
        if name.startswith("group__") and name.endswith(".xml"):
            root = ElementTree.parse(os.path.join(xml_dir, name)).getroot()
            group = root.find("compounddef/compoundname").text
            for q in root.iter("qualifiedname"):
                if "::" in q.text:
                    found[group] = q.text.rsplit("::", 1)[0].split("::")
                    break
    return found


_GROUP_NAMESPACES = _group_namespaces(breathe_projects["plate"])
_breathe_qualification = SphinxRenderer.get_qualification


def _qualification_in_groups(self):
    names = _breathe_qualification(self)
    if names or self.nesting_level > 0 or self.context.node_stack[0].node_type != "memberdef":
        return names
    for node in self.context.node_stack:
        if node.node_type == "compounddef" and node.kind == "group":
            return list(_GROUP_NAMESPACES.get(node.compoundname, []))
    return names


SphinxRenderer.get_qualification = _qualification_in_groups
breathe_default_project = "plate"
breathe_domain_by_extension = {"hpp": "cpp"}
breathe_show_include = True
breathe_show_define_initializer = True
breathe_show_enumvalue_initializer = True
