"""The wheel of ``make wheel``: manylinux, self-contained, installable without root or apt.

``make wheel`` repairs the wheel with auditwheel into build/wheel/ and runs this file
(LPTV_WHEEL_DIR names that folder; its constraints.txt holds the versions of the Makefile's
PIP_PINS). The checks:

- ``auditwheel show``: a manylinux tag, and every shared library the wheel takes from the system
  is one the manylinux policy allows (libc, libm, libstdc++, libgcc_s); SuiteSparse, OpenBLAS
  and its LAPACK, libgfortran and the rest travel in ``lptv.libs/``.
- The wheel is installed with pip into fresh venvs, without root: when the tests run as root
  (CI), pip and every run below go as the unprivileged user nobody (``setpriv``). The wheels of
  its dependencies are fetched first (pip's cache or PyPI, at the versions of PIP_PINS), the
  installs use only those (``--no-index``); no apt step. ``ldd`` of the installed module
  resolves every library outside the policy into the installed ``lptv.libs/``.
- The README's Python example of the paper (from a venv with the wheel, NumPy and SciPy only) and
  ``lptv demo`` (with the extras it uses: matplotlib, scikit-sundae) run with the Debian
  libraries hidden from the loader: in a private mount namespace (``unshare``, no root needed
  where user namespaces are allowed) an empty file is bound over every library the development
  build takes from the system outside the policy. The development build's module then fails
  to load (the hiding works); the installed wheel runs, and /proc/self/maps shows the bundled
  copies loaded and none of the hidden files.

What the unprivileged user reads of this checkout (README.md, the development build's module) is
copied into its own folder first: a checkout may sit where only its owner can read (a root
user's clone under /root, mode 700).
"""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile
from importlib import resources
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
WHEEL_DIR = Path(os.environ.get("LPTV_WHEEL_DIR", ROOT / "build" / "wheel"))
BIN = Path(sys.executable).parent          # the development venv's tools (auditwheel)
# Libraries that must travel in lptv.libs/ (SuiteSparse, OpenBLAS and its LAPACK); auditwheel
# names each copy <name>-<8 hex digits of its hash>.<version>.so or .so.<version>
MUST_BUNDLE = ("libcholmod", "libumfpack", "libklu", "libamd", "libopenblas", "liblapack")


def _is_copy(name, stem):
    return re.match(re.escape(stem) + r"[\w.-]*-[0-9a-f]{8}\.", name) is not None


def _run(argv, **kw):
    r = subprocess.run([str(a) for a in argv], capture_output=True, text=True, **kw)
    assert r.returncode == 0, f"{argv}: exit {r.returncode}\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}"
    return r


@pytest.fixture(scope="module")
def wheel():
    wheels = sorted(WHEEL_DIR.glob("lptv-*-manylinux_*.whl"))
    assert len(wheels) == 1, f"expected one repaired wheel in {WHEEL_DIR} (make wheel), got {wheels}"
    return wheels[0]


@pytest.fixture(scope="module")
def show(wheel):
    return json.loads(_run([BIN / "auditwheel", "show", "--json", wheel]).stdout)


def _policy(tag):
    """The manylinux policy of a tag (e.g. manylinux_2_35_x86_64), as auditwheel ships it."""
    text = (resources.files("auditwheel.policy") / "manylinux-policy.json").read_text()
    name = re.sub(r"_x86_64$", "", tag)
    (policy,) = [p for p in json.loads(text) if p["name"] == name or name in p["aliases"]]
    return policy


def _bundled(wheel):
    with zipfile.ZipFile(wheel) as z:
        return {Path(n).name for n in z.namelist() if n.startswith("lptv.libs/")}


def _ldd(path):
    """{soname: resolved path} of an ELF file, by the system's loader (ldd)."""
    out = _run(["ldd", path]).stdout
    return {m[0]: m[1] for m in re.findall(r"^\s*(\S+) => (\S+)", out, flags=re.M)}


def test_auditwheel_show_lists_nothing_outside_the_policy(wheel, show):
    tag = show["overall_tag"]
    assert tag.startswith("manylinux_") and wheel.name.endswith(f"-{tag}.whl")
    assert show["external_libs"] == {}
    allowed = set(_policy(tag)["lib_whitelist"])
    bundled = _bundled(wheel)
    for lib in show["versioned_symbols"]:
        assert lib in allowed or lib in bundled, lib
    for stem in MUST_BUNDLE:
        assert any(_is_copy(n, stem) for n in bundled), (stem, sorted(bundled))
    text = _run([BIN / "auditwheel", "-v", "show", wheel]).stdout
    assert "The wheel requires no external shared libraries" in text
    assert f'consistent with\nthe following platform tag: "{tag}"' in text or f'"{tag}"' in text
    with zipfile.ZipFile(wheel) as z:  # Eigen is a build-time dependency only: no headers shipped
        assert not [n for n in z.namelist() if "Eigen" in n or n.endswith((".h", ".hpp"))]


UNPRIVILEGED = 65534   # nobody: when the tests run as root, the installs and runs go as this user


def _user():
    """The prefix that drops root for a command (empty for a user who is not root)."""
    if os.geteuid() != 0:
        return []
    assert shutil.which("setpriv"), "setpriv (util-linux) is needed to drop root"
    return ["setpriv", f"--reuid={UNPRIVILEGED}", f"--regid={UNPRIVILEGED}", "--clear-groups"]


def _own(path):
    path.chmod(0o755)
    if os.geteuid() == 0:
        os.chown(path, UNPRIVILEGED, UNPRIVILEGED)
    return path


@pytest.fixture(scope="module")
def home():
    """A folder the unprivileged user owns: its HOME, the venvs, the working folders."""
    path = _own(Path(tempfile.mkdtemp(prefix="lptv-wheel-")))
    yield path
    shutil.rmtree(path, ignore_errors=True)


@pytest.fixture
def work(home, request):
    path = home / request.node.name
    path.mkdir()
    return _own(path)


def _readable_copy(src, folder):
    """A copy of src in folder that the unprivileged user can read: the checkout itself may not
    be readable to it (a clone under /root, mode 700)."""
    dst = Path(folder) / Path(src).name
    shutil.copyfile(src, dst)
    dst.chmod(0o644)
    return dst


def _as_user(argv, home, cwd=None, **kw):
    """argv as the unprivileged user, with a plain environment (no venv, no library path)."""
    drop = ("LD_LIBRARY_PATH", "LD_PRELOAD", "PYTHONPATH", "VIRTUAL_ENV", "PIP_CACHE_DIR")
    env = {k: v for k, v in os.environ.items() if k not in drop}
    env.update(HOME=str(home), PATH="/usr/bin:/bin", MPLBACKEND="Agg", PIP_NO_CACHE_DIR="1")
    return subprocess.run([*_user(), *map(str, argv)], capture_output=True, text=True,
                          cwd=cwd or home, env=env, **kw)


def _ok(r):
    assert r.returncode == 0, f"{r.args}: exit {r.returncode}\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}"
    return r


@pytest.fixture(scope="module")
def wheels(wheel, home):
    """The wheel and the wheels of everything it and its two extras need (--only-binary: nothing
    is built), fetched by pip at the versions of the Makefile's pins."""
    path = home / "wheels"
    constraints = WHEEL_DIR / "constraints.txt"
    pin = ["-c", constraints] if constraints.exists() else []
    _run([sys.executable, "-m", "pip", "download", "-q", "--disable-pip-version-check", "--only-binary",
          ":all:", *pin, "-d", path, f"{wheel}[plots,timedomain]"], timeout=900)
    for p in (path, *path.iterdir()):
        p.chmod(0o755 if p.is_dir() else 0o644)
    return path


def _interpreter():
    """The fresh venvs' Python: this one's, or for the unprivileged user Debian's of the same
    version (this one may sit where only root can read, e.g. /root/.pyenv)."""
    if os.geteuid() != 0:
        return sys.executable
    exe = Path(f"/usr/bin/python{sys.version_info.major}.{sys.version_info.minor}")
    assert exe.exists(), f"{exe} (Debian's python3 with python3-venv) is needed to test as a user"
    return exe


def _fresh_venv(home, wheels, name, extras=""):
    """A fresh venv with the wheel installed by pip as the unprivileged user (no root, no apt,
    no build, no index: the fetched wheels only)."""
    path = home / name
    _ok(_as_user([_interpreter(), "-m", "venv", path], home))
    (wheel,) = wheels.glob("lptv-*.whl")
    _ok(_as_user([path / "bin" / "python", "-m", "pip", "install", "-q", "--disable-pip-version-check",
                  "--no-index", "--find-links", wheels, f"{wheel}{extras}"], home, timeout=900))
    return path


@pytest.fixture(scope="module")
def bare(home, wheels):
    """The wheel alone: lptv with NumPy and SciPy, its only requirements."""
    return _fresh_venv(home, wheels, "bare")


@pytest.fixture(scope="module")
def venv(home, wheels):
    """The wheel with the extras lptv demo uses: matplotlib (plots) and scikit-sundae (timedomain)."""
    return _fresh_venv(home, wheels, "full", "[plots,timedomain]")


def _installed_core(venv):
    out = _run([venv / "bin" / "python", "-c", "import lptv._core as c; print(c.__file__)"],
               cwd=venv).stdout
    return Path(out.strip().splitlines()[-1])


def test_installed_module_resolves_to_its_own_libraries(venv, show):
    core = _installed_core(venv)
    assert core.is_relative_to(venv), core
    libs_dir = (core.parent.parent / "lptv.libs").resolve()
    allowed = set(_policy(show["overall_tag"])["lib_whitelist"])
    files = [core, *libs_dir.iterdir()]
    for elf in files:
        for name, where in _ldd(elf).items():
            if name in allowed:
                continue
            assert Path(where).resolve().parent == libs_dir, f"{elf.name} takes {name} from {where}"
    names = {f.name for f in libs_dir.iterdir()}
    for stem in MUST_BUNDLE:
        assert any(_is_copy(n, stem) for n in names), stem


@pytest.fixture(scope="module")
def hidden(show):
    """The files the development build's module loads from the system outside the policy."""
    import lptv._core

    allowed = set(_policy(show["overall_tag"])["lib_whitelist"])
    files = sorted({os.path.realpath(p) for n, p in _ldd(lptv._core.__file__).items() if n not in allowed})
    for stem in ("libcholmod", "libumfpack", "libklu", "libopenblas", "liblapack"):
        assert any(Path(f).name.startswith(stem) for f in files), (stem, files)
    return files


def _run_hidden(argv, hidden, home, cwd, **kw):
    """argv as the unprivileged user in a private mount namespace where every file of ``hidden``
    is empty (a user namespace maps the user to root there, which may bind-mount)."""
    if shutil.which("unshare") is None:
        pytest.skip("no unshare (util-linux) to hide the Debian libraries")
    probe = _as_user(["unshare", "--mount", "--map-root-user", "true"], home)
    if probe.returncode != 0:
        pytest.skip(f"unshare --mount --map-root-user is not allowed here: {probe.stderr[-300:]}")
    empty = home / "empty"
    empty.write_bytes(b"")
    empty.chmod(0o644)
    script = ('e=$1; shift; while [ "$1" != -- ]; do mount --bind "$e" "$1" || exit 97; shift; done; '
              'shift; exec "$@"')
    return _as_user(["unshare", "--mount", "--map-root-user", "sh", "-c", script, "sh", empty, *hidden,
                     "--", *argv], home, cwd=cwd, **kw)


def test_the_development_build_needs_the_hidden_libraries(hidden, home, work):
    """The control: the module built against the Debian libraries loads (dlopen) as the user,
    and with them hidden it cannot."""
    import lptv._core

    module = _readable_copy(lptv._core.__file__, work)   # the same file, where the user can read it
    load = [_interpreter(), "-c", "import ctypes, sys; ctypes.CDLL(sys.argv[1])", module]
    _ok(_as_user(load, home, cwd=work))
    r = _run_hidden(load, hidden, home, work)
    assert r.returncode not in (0, 97), r.stderr
    assert "file too short" in r.stderr or "cannot open" in r.stderr, r.stderr


README_RUN = r'''
import json, re, sys
from pathlib import Path

block = [b for b in re.findall(r"```python\n(.*?)```", Path(sys.argv[1]).read_text(), flags=re.S)
         if "lptv.frozen_poles(res.model" in b][0]
ns = {}
exec(compile(block, "README.md", "exec"), ns)
import lptv, lptv._core
maps = sorted({line.split()[-1] for line in open("/proc/self/maps") if ".so" in line})
res = ns["res"]
uid_map = open("/proc/self/uid_map").read().split()    # inside, outside, count
print(json.dumps({"lptv": lptv.__file__, "core": lptv._core.__file__, "maps": maps, "uid_map": uid_map,
                  "converged": bool(res.converged), "residue_ok": bool(res.residue_ok)}))
'''


def test_readme_example_runs_from_the_wheel_with_the_debian_libraries_hidden(bare, hidden, home, work):
    """The README's example of the paper in the venv that holds the wheel and NumPy and SciPy only."""
    venv = bare
    script = work / "readme_example.py"
    script.write_text(README_RUN)
    script.chmod(0o644)
    readme = _readable_copy(ROOT / "README.md", work)
    r = _run_hidden([venv / "bin" / "python", script, readme], hidden, home, work, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert out["converged"] and out["residue_ok"]
    if os.geteuid() == 0:  # root inside the namespace is the unprivileged user outside it
        assert out["uid_map"][:2] == ["0", str(UNPRIVILEGED)], out["uid_map"]
    assert Path(out["lptv"]).is_relative_to(venv) and Path(out["core"]).is_relative_to(venv)
    assert (work / "model.json").exists()
    libs_dir = (Path(out["core"]).parent.parent / "lptv.libs").resolve()
    loaded = [Path(p).resolve() for p in out["maps"]]
    assert not set(map(str, loaded)) & set(hidden), "a hidden library was loaded"
    for stem in MUST_BUNDLE:  # the bundled copies are the ones in memory
        assert any(p.parent == libs_dir and _is_copy(p.name, stem) for p in loaded), stem
    for p in loaded:
        if any(p.name.startswith(stem) for stem in ("libcholmod", "libumfpack", "libklu", "liblapack")):
            assert p.parent == libs_dir, p


def test_lptv_demo_without_its_extras_names_them(bare, home, work):
    r = _as_user([bare / "bin" / "lptv", "demo", "--out", work / "demo"], home, cwd=work)
    assert r.returncode == 2 and "pip install 'lptv[plots]'" in r.stderr, r.stderr[-2000:]
    assert len(r.stderr.strip().splitlines()) == 1


def test_lptv_demo_runs_from_the_wheel_with_the_debian_libraries_hidden(venv, hidden, home, work):
    r = _run_hidden([venv / "bin" / "lptv", "demo", "--out", work / "demo"], hidden, home, work,
                    timeout=600)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-3000:]
    assert "done in" in r.stdout
    for name in ("report.html", "summary.json", "model_wgtls.json"):
        assert (work / "demo" / name).stat().st_size > 0, name
