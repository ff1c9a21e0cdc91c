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
exclude_patterns = ["_build", "_generated"]

# the pages are Markdown (MyST); headings get anchors so pages can link to sections
myst_heading_anchors = 3

# numpydoc-style docstrings
napoleon_google_docstring = False
napoleon_numpy_docstring = True

autodoc_member_order = "bysource"
autodoc_typehints = "description"

html_theme = "alabaster"


def _criteria_page():
    """docs/_generated/criteria.md: the criteria as the code defines them (the registry that
    print(), the CLI and every report read), included by verification.md."""
    from discovery.vibroimpact.verify.criteria import CRITERIA, MOTION_DEFINITIONS

    lines = []
    for c in (*CRITERIA.values(), *MOTION_DEFINITIONS.values()):
        lines.append(f"- **{c.name}** = `{c.formula}`: {c.meaning} (unit {c.unit})")
    out = Path(__file__).parent / "_generated" / "criteria.md"
    out.parent.mkdir(exist_ok=True)
    text = "\n".join(lines) + "\n"
    if not out.exists() or out.read_text() != text:
        out.write_text(text)


_criteria_page()
html_title = "vidi"
