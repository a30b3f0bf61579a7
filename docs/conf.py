"""Sphinx configuration of aerocontrol's documentation site.

Built by ``bash scripts/docs.sh`` (warnings are errors, every cross-reference must resolve,
every gallery script runs; the pages' examples run in the tests
(tests/test_docs.py)). The build needs no network: the
inventories of the projects the site links to are read from ``docs/_inventories`` (see its
README), and external links are not checked.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import aerocontrol

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS))

project = "aerocontrol"
author = "the aerocontrol developers"
copyright = "2026, the aerocontrol developers"
release = aerocontrol.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "api_pages",
    "aircraft_keys",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_inventories", "gallery/*.ipynb", "gallery/*.py", "**.zip"]

# Every reference must resolve (scripts/docs.sh adds -W -n).
nitpicky = True
# numpydoc's parameter types are prose ("array_like (n, n)"), not cross-references.
numpydoc_xref_param_type = False
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
# Signatures without annotations: the docstrings' Parameters say the types in words.
autodoc_typehints = "none"
autosummary_generate = False
autosummary_imported_members = False

# Offline inventories (docs/_inventories/README.md); projects without one are not linked.
_INVENTORIES = {
    "python": "https://docs.python.org/3/",
    "scipy": "https://docs.scipy.org/doc/scipy/",
    "numpy": "https://numpy.org/doc/stable/",
    "matplotlib": "https://matplotlib.org/stable/",
    "control": "https://python-control.readthedocs.io/en/latest/",
}
intersphinx_mapping = {
    name: (url, str(DOCS / "_inventories" / f"{name}.inv"))
    for name, url in _INVENTORIES.items()
    if (DOCS / "_inventories" / f"{name}.inv").is_file()
}
intersphinx_timeout = 5
# A reference to a project whose inventory is absent is written as plain text, not an error.
nitpick_ignore_regex = [
    (r"py:.*", rf"{name}(\..*)?")
    for name in ("numpy", "np", "matplotlib", "control", "dask", "distributed")
    if name not in intersphinx_mapping
]

myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]


sphinx_gallery_conf = {
    "examples_dirs": str(DOCS.parent / "examples"),
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"(__init__|_common)\.py",
    "abort_on_example_error": True,
    "only_warn_on_example_error": False,
    "download_all_examples": False,
    "within_subsection_order": "FileNameSortKey",
    "remove_config_comments": True,
    "matplotlib_animations": False,
    "plot_gallery": os.environ.get("AEROCONTROL_DOCS_GALLERY", "True"),
}

html_theme = "furo"
html_title = f"aerocontrol {release}"
html_static_path: list[str] = []
html_show_sourcelink = False
