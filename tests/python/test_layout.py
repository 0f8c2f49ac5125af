"""The package's shape (DESIGN.md): no module imports another that imports it back, at any level
(a lazy import inside a function counts: it is a circle all the same), and no module is longer
than one sitting's reading (800 lines)."""
import ast
from pathlib import Path

import lptv

PACKAGE = Path(lptv.__file__).resolve().parent


def _modules():
    mods = {}
    for p in PACKAGE.rglob("*.py"):
        parts = p.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        mods[name] = p
    return mods


def _imports(name, path, mods):
    """The package's modules that ``name`` imports (``from . import x`` names the module x)."""
    pkg = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = pkg.split(".")[:len(pkg.split(".")) - (node.level - 1)]
                base = ".".join(up + ([node.module] if node.module else []))
            if node.module:
                out.add(base)
            out |= {f"{base}.{a.name}" for a in node.names}
    return {m for m in out if m in mods and m != name}


def test_the_checker_sees_a_circle(tmp_path):
    """The check itself on a made-up package: a <-> b through a lazy import is found."""
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from .b import f\n")
    (pkg / "b.py").write_text("def f():\n    from . import a\n")
    mods = {"pkg": pkg / "__init__.py", "pkg.a": pkg / "a.py", "pkg.b": pkg / "b.py"}
    assert _imports("pkg.a", mods["pkg.a"], mods) == {"pkg.b"}
    assert _imports("pkg.b", mods["pkg.b"], mods) == {"pkg.a"}


def test_no_module_imports_one_that_imports_it_back():
    mods = _modules()
    assert len(mods) > 40
    edges = {m: _imports(m, p, mods) for m, p in mods.items()}
    circles = sorted({tuple(sorted((a, b))) for a in edges for b in edges[a] if a in edges[b]})
    assert not circles, circles



# What the documents cite lives in the repository: a paper or a lecture by its authors and title,
# never by a file outside it.
OUTSIDE = ("seeds/", "../shared", "shared/seeds", "REFERENCES.md")


def _documents(root):
    docs = root / "docs"
    files = [root / "README.md", root / "METHOD.md", root / "DESIGN.md", root / "bench" / "RESULTS.md",
             root / "bench" / "HISTORY.md"]
    files += [p for ext in ("md", "rst") for p in docs.rglob(f"*.{ext}")
              if "auto_examples" not in p.relative_to(docs).parts]
    return files + sorted((docs / "examples").glob("*.py"))


def test_the_documents_name_no_file_outside_the_repository():
    root = Path(__file__).resolve().parents[2]
    files = _documents(root)
    assert len(files) > 20 and all(p.exists() for p in files[:5])
    found = [f"{p.relative_to(root)}:{i}: {line.strip()}" for p in files
             for i, line in enumerate(p.read_text().splitlines(), 1) if any(s in line for s in OUTSIDE)]
    assert not found, "\n".join(found)


MAX_LINES = 800


def test_no_module_is_longer_than_one_sitting():
    long = {m: n for m, p in _modules().items() if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert not long, long
