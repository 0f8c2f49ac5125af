"""Sphinx configuration of the lptv documentation (make docs builds it into build/docs/html).

The pages: the README (its links pointed at the pages here), the user guide (docs/guide), the API
reference from the numpydoc docstrings of the installed package, a gallery of examples that
sphinx-gallery runs on every build (an error in one fails the build), METHOD.md, DESIGN.md,
bench/RESULTS.md and bench/HISTORY.md.
"""
import os
import re
from pathlib import Path

from sphinx.util import logging

import lptv

logger = logging.getLogger(__name__)

ROOT = Path(__file__).resolve().parents[1]

project = "lptv"
author = "the lptv authors"
copyright = "the lptv authors"
release = version = lptv.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.intersphinx",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "examples/GALLERY_HEADER.rst", "auto_examples/*.ipynb",
                    "auto_examples/*.py", "auto_examples/*.zip"]
html_theme = "furo"
html_title = f"lptv {release}"
templates_path = []
nitpicky = False

# The API reference: the docstrings are numpydoc; members are listed by autodoc (not by numpydoc's
# autosummary tables, which would need a stub page per member).
autodoc_member_order = "bysource"
autodoc_typehints = "none"
autodoc_default_options = {"members": True}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3

intersphinx_mapping = {}

# The gallery: every script in examples/ runs at each build; the first error stops it.
sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r".*\.py$",
    "run_stale_examples": True,
    "abort_on_example_error": True,
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "min_reported_time": 0,
    "write_computation_times": False,
    "reset_modules": ("matplotlib",),
    "capture_repr": (),   # what an example prints shows, not the value of its last line
}

# The Markdown files of the source tree, read into the pages of the same name (each page in
# docs/ is a stub): README.md with its links to the source tree turned into the site's pages.
# The user guide (docs/guide/*.md) is read where it is; its links into the source tree
# (../../METHOD.md) and to the gallery's scripts (../examples/plot_*.py) turn into the site's pages.
_PAGES = {"readme": "README.md", "method": "METHOD.md", "design": "DESIGN.md",
          "results": "bench/RESULTS.md", "history": "bench/HISTORY.md"}
_LINKS = {"bench/RESULTS.md": "results.md", "bench/HISTORY.md": "history.md", "DESIGN.md": "design.md",
          "METHOD.md": "method.md", "README.md": "readme.md"}
_BENCH_LINKS = {"RESULTS.md": "results.md", "HISTORY.md": "history.md"}
_GALLERY_LINK = re.compile(r"\]\(\.\./examples/(plot_\w+)\.py\)")
_CODE_SPAN = re.compile(r"(`+)(?:(?!\n[ \t]*\n)[\s\S])*?\1")   # may span lines, not paragraphs
_WORD_STAR = re.compile(r"(?<=[A-Za-z0-9])\*(?=[A-Za-z0-9])")


def _plain_maths(text):
    """The files write maths in plain text (a_{n,k}, (B U)_l, 2*pi), which CommonMark could pair
    into emphasis across a formula: outside code every underscore (none marks emphasis there)
    and every star between two word characters is escaped. Fenced and indented code, and code
    spans, are left as they are."""
    out, prose, fenced, code = [], [], False, False

    def flush():
        if prose:
            chunk, pos, parts = "\n".join(prose), 0, []
            for m in _CODE_SPAN.finditer(chunk):
                parts += [_escape(chunk[pos:m.start()]), m.group(0)]
                pos = m.end()
            out.extend("".join(parts + [_escape(chunk[pos:])]).split("\n"))
            prose.clear()

    previous = ""
    for line in text.split("\n"):
        fence = line.lstrip().startswith("```")
        code = line.startswith("    ") and (not previous.strip() or code) and not fenced
        if fenced or fence or code:
            flush()
            out.append(line)
        else:
            prose.append(line)
        if fence:
            fenced = not fenced
        previous = line
    flush()
    return "\n".join(out)


def _escape(s):
    return _WORD_STAR.sub(r"\\*", s.replace("_", "\\_"))


def _markdown_page(app, docname, source):
    if docname.startswith("guide/"):
        text = source[0]
        for old, new in _LINKS.items():
            text = text.replace(f"](../../{old})", f"](../{new})")
        source[0] = _plain_maths(_GALLERY_LINK.sub(r"](../auto_examples/\1.rst)", text))
        return
    if docname not in _PAGES:
        return
    text = (ROOT / _PAGES[docname]).read_text()
    if docname == "readme":
        for old, new in _LINKS.items():
            text = text.replace(f"]({old})", f"]({new})")
        text = text.replace("](docs/", "](")
    if docname in ("results", "history"):
        for old, new in _BENCH_LINKS.items():
            text = text.replace(f"]({old})", f"]({new})")
    source[0] = _plain_maths(text)


_LITERAL = re.compile(r"(``.+?``)")
_TABLE = re.compile(r"\s*(\| |\+[-=])")  # a line block or a table row keeps its bars


def _plain_bars(app, what, name, obj, options, lines):
    """The docstrings write maths in plain text as METHOD.md does, |x| for an absolute value;
    reStructuredText would read |x| as a substitution, so the bars outside literals are escaped."""
    for i, line in enumerate(lines):
        if "|" in line and not _TABLE.match(line):
            parts = _LITERAL.split(line)
            lines[i] = "".join(p if p.startswith("``") else p.replace("|", "\\|") for p in parts)


def _api_covers_all(app):
    """Every public name of the package (lptv.__all__) has its entry in api.rst: a new function
    that is not documented there is a warning, so make docs (-W) fails."""
    text = (Path(app.srcdir) / "api.rst").read_text()
    documented = set(re.findall(r"^\.\. auto(?:function|class|exception|data):: (?:lptv\.)?(\w+)\s*$",
                                text, flags=re.M))
    for name in sorted(set(lptv.__all__) - documented):
        logger.warning(f"api.rst does not document lptv.{name} (it is in lptv.__all__)")


def setup(app):
    app.connect("builder-inited", _api_covers_all)
    app.connect("source-read", _markdown_page)
    app.connect("autodoc-process-docstring", _plain_bars)
