"""Sphinx configuration of the vidi documentation site (``make docs``)."""

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

project = "vibroimpact-discovery (vidi)"
author = "the vidi authors"
copyright = "the vidi authors, BSD-3-Clause"

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build"]

# the pages are Markdown (MyST); headings get anchors so pages can link to sections
myst_heading_anchors = 3

# numpydoc-style docstrings
napoleon_google_docstring = False
napoleon_numpy_docstring = True

autodoc_member_order = "bysource"
autodoc_typehints = "description"

html_theme = "alabaster"
html_title = "vidi"
