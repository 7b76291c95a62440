"""Sphinx configuration of wgcad's site: the guide (README), the API reference from the docstrings (numpydoc),
the models, the design keys, the architecture. Built with warnings as errors by tests/test_docs_site.py:
``python -m sphinx -W -c docs -b html . docs/_build/html``: the source folder is the checkout, so the README and the
changelog are pages as they are and their relative links (``docs/models.md``) resolve; only the files named in
``include_patterns`` are read."""

import os
import sys

sys.path.insert(0, os.path.abspath(os.path.join(os.path.dirname(__file__), "..")))
import wgcad  # noqa: E402

project = "wgcad"
copyright = "2026, the wgcad developers"
release = version = wgcad.__version__

extensions = ["sphinx.ext.autodoc", "numpydoc", "myst_parser"]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "docs/index"
include_patterns = ["README.md", "CHANGELOG.md", "docs/*.md", "docs/*.rst"]
exclude_patterns = ["docs/_build", "docs/README.md"]
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]
autodoc_typehints = "none"
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
html_theme = "alabaster"
