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
html_title = "vidi"

GENERATED = Path(__file__).parent / "_generated"


def _write(name, text):
    GENERATED.mkdir(exist_ok=True)
    out = GENERATED / name
    if not out.exists() or out.read_text() != text:
        out.write_text(text)


def _criteria_page():
    """_generated/criteria.md: the criteria as the code defines them (the registry that
    print(), the CLI and every report read), included by verification.md."""
    from discovery.vibroimpact.verify.criteria import CRITERIA, MOTION_DEFINITIONS

    lines = []
    for c in (*CRITERIA.values(), *MOTION_DEFINITIONS.values()):
        lines.append(f"- **{c.name}** = `{c.formula}`: {c.meaning} (unit {c.unit})")
    _write("criteria.md", "\n".join(lines) + "\n")


def _cli_page():
    """_generated/cli-help.md: every command's ``--help`` as vidi prints it, included by
    cli.md."""
    import argparse
    import os

    from discovery.cli import _parser

    os.environ["COLUMNS"] = "100"  # argparse wraps at the terminal's width

    def walk(parser, path):
        yield path, parser.format_help()
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    yield from walk(sub, [*path, name])

    parts = []
    for path, text in walk(_parser(), ["vidi"]):
        parts.append(f"### `{' '.join(path)}`\n\n```text\n{text.rstrip()}\n```\n")
    _write("cli-help.md", "\n".join(parts))


_criteria_page()
_cli_page()
