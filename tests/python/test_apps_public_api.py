"""The command line and its jobs (lptv.apps) import nothing private from the library.

They name the library absolutely (``from lptv import ...``): a relative import could reach past
the public names without showing it.
"""
import ast
from pathlib import Path

import lptv.apps

APPS = Path(lptv.apps.__file__).parent


def private_imports(path):
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module.split(".")[0] == "lptv":
            names = node.module.split(".") + [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level > 0:
            yield f"line {node.lineno}: relative import"
            continue
        elif isinstance(node, ast.Import):
            names = [part for a in node.names if a.name.split(".")[0] == "lptv"
                     for part in a.name.split(".")]
        else:
            continue
        if any(n.startswith("_") for n in names):
            yield f"line {node.lineno}: {'.'.join(names)}"


def test_apps_use_only_public_names():
    found = {p.name: list(private_imports(p)) for p in sorted(APPS.glob("*.py"))}
    assert len(found) >= 5
    assert not {k: v for k, v in found.items() if v}
