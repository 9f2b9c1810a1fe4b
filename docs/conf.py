"""Sphinx configuration of alte's documentation site (``make docs``).

Sphinx with myst-nb (Markdown pages, notebooks executed at build time) and the PyData
theme; ``environment.md`` says why. The tutorials run on small inputs in the build,
each kernel in a temporary folder (nothing is written beside the sources).
"""

from __future__ import annotations

import os
import sys
from datetime import date
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))
# The tutorials' kernels inherit this environment: figures inline (make exports Agg for
# everything else it runs), 3D views as images, off-screen.
os.environ["MPLBACKEND"] = "module://matplotlib_inline.backend_inline"
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
os.environ.setdefault("ALTE_RENDER", "static")

import alte  # noqa: E402

project = "alte"
author = "the alte developers"
copyright = f"{date.today().year}, {author}"
release = version = alte.__version__

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinxarg.ext",
    "sphinx_design",
    "alte_docs",
]

root_doc = "index"
exclude_patterns = ["_build", "**/.ipynb_checkpoints", "jupyter_execute", "README.md"]
source_suffix = {".md": "myst-nb", ".ipynb": "myst-nb"}

# MyST: ::: fences, definition lists, anchors for ## headings (links like page.md#section).
myst_enable_extensions = ["colon_fence", "deflist"]
myst_heading_anchors = 3

# Notebooks: executed on every build (the tutorials' parameters are small), in a temporary
# folder, a failing cell fails the build. ALTE_DOCS_EXECUTE=cache re-executes only the
# notebooks whose code changed (myst-nb's jupyter-cache in docs/_build/.jupyter_cache:
# quick rebuilds while writing; a change in alte alone does not re-run them).
nb_execution_mode = os.environ.get("ALTE_DOCS_EXECUTE", "force")
nb_execution_in_temp = True
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_execution_timeout = 300
# Tutorials on the real recordings run only where ../shared/realdata is (as the tests that
# need it skip without it): elsewhere their pages show the code, unexecuted.
REAL_TUTORIALS = ["tutorials/map-a-terrain-tile.ipynb", "tutorials/compare-mappers.ipynb"]
nb_execution_excludepatterns = [] if (DOCS.parent.parent / "shared" / "realdata").is_dir() \
    else REAL_TUTORIALS
# ALTE_DOCS_TUTORIALS=skip: the tutorials shown unexecuted, every other page as usual (the
# results pages still compute their tables). make test builds the site so (links,
# references, warnings, in a fraction of the time); make docs and make check-full run them.
if os.environ.get("ALTE_DOCS_TUTORIALS", "run") == "skip":
    nb_execution_excludepatterns = ["tutorials/*"]
nb_merge_streams = True

# API reference from the docstrings: members as __all__ lists them, in source order.
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "signature"
autodoc_typehints_format = "short"
autodoc_preserve_defaults = True
# alte's signatures are annotated (mypy strict), never typed in "# type:" comments: reading
# every function's source again for such comments changes nothing on the site.
autodoc_use_type_comments = False

html_theme = "pydata_sphinx_theme"
html_title = "alte"
html_static_path = ["_static"]
html_theme_options = {
    "navigation_depth": 2,
    "show_toc_level": 2,
    "navbar_align": "left",
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_sidebars = {"index": [], "getting-started": []}
html_show_sourcelink = False
# The theme's light/dark switch starts from "auto" (an empty mode is refused by its script).
html_context = {"default_mode": "auto"}
