"""Sphinx configuration of the sphgen documentation (``make docs``)."""
import importlib.util
import os
import re
import sys

project = "sphgen"
author = "the sphgen authors"
release = "0.1.0"

extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon", "sphinx.ext.mathjax"]

source_suffix = {".rst": "restructuredtext"}
master_doc = "index"
exclude_patterns = ["_build", "examples"]
html_theme = "alabaster"
html_static_path = []

autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "show-inheritance": True}
napoleon_numpy_docstring = True
napoleon_google_docstring = True

_HERE = os.path.dirname(os.path.abspath(__file__))
_ROOT = os.path.dirname(_HERE)


def _document_this_checkout():
    """Import sphgen and its top-level folders (equations, schemes, applications) from the
    checkout these docs belong to, not from wherever sphgen was installed (an editable
    install maps ``sphgen.schemes`` to the folder of the install's own checkout)."""
    sys.path.insert(0, _ROOT)
    import sphgen  # noqa: F401  (the checkout's, now first on sys.path)
    for name in ("equations", "schemes", "applications"):
        path = os.path.join(_ROOT, name)
        spec = importlib.util.spec_from_file_location(
            f"sphgen.{name}", os.path.join(path, "__init__.py"),
            submodule_search_locations=[path])
        module = importlib.util.module_from_spec(spec)
        sys.modules[spec.name] = module
        spec.loader.exec_module(module)


_document_this_checkout()


def _validation_page(app, docname, source):
    """validation.md is written by hand and may not exist yet: include it only if it does."""
    if docname != "validation":
        return
    md = os.path.join(_HERE, "validation.md")
    app.env.note_dependency(md)  # re-read this page when the file appears or changes
    if os.path.exists(md):
        source[0] += "\n.. literalinclude:: validation.md\n   :language: none\n"
    else:
        source[0] += "\n*docs/validation.md has not been written yet.*\n"


_LITERAL = re.compile(r"(`+[^`]*`+)")


def _escape_bars(line):
    """``|x|`` in running text is a norm, not an rST substitution: escape bars outside backticks."""
    parts = _LITERAL.split(line)
    return "".join(p if i % 2 else p.replace("|", "\\|") for i, p in enumerate(parts))


def _plain_text_math(app, what, name, obj, options, lines):
    """Docstrings write equations as plain text (``|r_ab|``, ``|det A|``); keep literal blocks."""
    block_indent = None
    for k, line in enumerate(lines):
        indent = len(line) - len(line.lstrip())
        if block_indent is not None and line.strip() and indent <= block_indent:
            block_indent = None
        if block_indent is None:
            lines[k] = _escape_bars(line)
            if line.rstrip().endswith("::"):
                block_indent = indent


def setup(app):
    app.connect("source-read", _validation_page)
    app.connect("autodoc-process-docstring", _plain_text_math)
