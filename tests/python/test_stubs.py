"""The type stubs shipped with the package (lptv/_core.pyi) describe the compiled module as built."""
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import lptv


def test_stubs_match_the_compiled_module(tmp_path):
    shipped = Path(lptv.__file__).with_name("_core.pyi")
    assert shipped.exists(), "the wheel must ship lptv/_core.pyi"
    if shutil.which("pybind11-stubgen", path=str(Path(sys.executable).parent)) is None:
        pytest.fail("pybind11-stubgen is missing (it is pinned in the Makefile)")
    subprocess.run([str(Path(sys.executable).with_name("pybind11-stubgen")), "lptv._core", "-o", str(tmp_path)],
                   check=True, capture_output=True)
    fresh = (tmp_path / "lptv" / "_core.pyi").read_text()
    assert shipped.read_text() == fresh, "python/lptv/_core.pyi is out of date: run `make stubs`"
