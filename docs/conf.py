"""Sphinx configuration of the sphgen documentation (``make docs``)."""
import os

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


def setup(app):
    app.connect("source-read", _validation_page)
