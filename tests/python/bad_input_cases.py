"""The table of bad inputs through the public Python API and the command line.

Each Python case is a call and what it must give: a ValueError (or the stated exception type)
whose message names the argument (a regular expression), or a correct result (a check computed
here by an independent route), or a warning with a meaningful result. Each command-line case is
the arguments of ``lptv``; it must exit with status 2 and print exactly one non-empty line on
stderr naming the option (or the file), without a traceback. ``klass`` sorts the cases into the
classes of bad input the counts are given for.

bad_input_runner.py runs the cases and sorts what happens into OUTCOMES; used by
tests/python/test_bad_inputs.py and bench/python/bad_inputs.py.
"""
from __future__ import annotations

import functools
import importlib
import json
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional

import numpy as np
import lptv


NaN, INF = float("nan"), float("inf")
ROOT = Path(__file__).resolve().parents[2]
# The child processes import the lptv this process imports (the installed package under `make
# test`, the source tree with PYTHONPATH=python), never another copy.
PYTHONPATH = str(Path(lptv.__file__).resolve().parents[1])


@dataclass(frozen=True)
class Case:
    id: str
    klass: str
    """type, nan/inf, shape, size, range, overflow, file, value (a valid edge case) or cli."""
    call: Optional[Callable] = None
    exc: type = ValueError
    match: str = ""
    """Regular expression the message must contain (re.search)."""
    check: Optional[Callable] = None
    """For a valid input: result -> bool, True when the result is right."""
    warning: Optional[str] = None
    """For a valid input that must warn: the name of the lptv warning class."""
    argv: tuple = ()
    """Command-line cases: the arguments after ``python -m lptv`` ({dir} is the files' folder)."""

    @property
    def expected(self):
        if self.argv:
            return "clear error"
        if self.check is None:
            return "clear error"
        return "warning" if self.warning is not None else "correct result"


# ------------------------------------------------------------------------------- fixtures

@functools.lru_cache(None)
def _lptv():
    import lptv

    return lptv


@functools.lru_cache(None)
def lti():
    return _lptv().Model([[2.0], [1.0]], [[1.0]], w0=0.1)          # 1 / (s + 2)


@functools.lru_cache(None)
def ltv():
    return _lptv().Model([[2.0 - 0.2j, 2.0, 2.0 + 0.2j], [0, 1, 0]], [[1.0]], w0=0.1)


@functools.lru_cache(None)
def dt_model():
    return _lptv().Model([[0.5], [1.0]], [[1.0]], w0=2 * np.pi / 8, ts=1.0)


@functools.lru_cache(None)
def periods():
    """4 noisy periods of 256 samples of 1 / (s + 2) under a 59-line multisine."""
    lptv = _lptv()
    ms = lptv.multisine(range(1, 60), 256, seed=0)
    y1 = lptv.time_signal(lptv.simulate(lti(), ms.spectrum), 256)
    rng = np.random.default_rng(1)
    u = ms.periods(4) + 1e-3 * rng.standard_normal((4, 256))
    y = np.tile(y1, (4, 1)) + 1e-3 * rng.standard_normal((4, 256))
    return u, y


def U():
    return periods()[0]


def Y():
    return periods()[1]


@functools.lru_cache(None)
def data():
    return _lptv().FrequencyData.from_periods(*periods(), w0=0.1)


@functools.lru_cache(None)
def fit():
    return _lptv().identify(*periods(), na=1, nb=0, w0=0.1, method="wgtls")


@functools.lru_cache(None)
def folder():
    return Path(tempfile.mkdtemp(prefix="lptv-bad-inputs-"))


def write(name, content):
    """A file in the cases' folder: bytes, text, or a dict of arrays (saved as .npz or .mat)."""
    path = folder() / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif isinstance(content, str):
        path.write_text(content)
    elif name.endswith(".npz"):
        np.savez(path, **content)
    elif name.endswith(".mat"):
        import scipy.io

        scipy.io.savemat(path, content)
    return path


@functools.lru_cache(None)
def ins_record():
    """12 periods of 50 samples of cosines on lines 2, 5 and 7, and a filtered copy, with noise."""
    k = np.arange(600)
    rng = np.random.default_rng(0)
    u = sum(np.cos(2 * np.pi * l * k / 50 + l) for l in (2, 5, 7)) + 1e-3 * rng.standard_normal(600)
    y = np.convolve(u, [0.5, 0.5])[:600] + 1e-3 * rng.standard_normal(600)
    return u, y


def good_npz():
    u, y = periods()
    return write("good.npz", {"u": u, "y": y, "w0": 0.1})


def model_json(**change):
    d = lti().to_dict()
    d.update(change)
    for k in [k for k, v in change.items() if v is _DROP]:
        del d[k]
    return write("model.json", json.dumps(d))


_DROP = object()
JUNK = bytes(range(256)) * 8


# ------------------------------------------------------------------------- value families

INT_BAD = [("none", None, "type"), ("str", "abc", "type"), ("complex", 1j, "type"), ("list", [1, 2], "shape"),
           ("nan", NaN, "nan/inf"), ("inf", INF, "nan/inf"), ("fraction", 2.5, "type"),
           ("negative", -1, "range"), ("2**31", 2**31, "overflow"), ("2**63", 2**63, "overflow"),
           ("-2**31", -2**31, "overflow")]
FLOAT_BAD = [("none", None, "type"), ("str", "abc", "type"), ("complex", 1j, "type"), ("list", [1.0, 2.0], "shape"),
             ("nan", NaN, "nan/inf"), ("inf", INF, "nan/inf"), ("zero", 0.0, "range"), ("negative", -1.0, "range")]


def names(arg):
    """The message names the argument and says what is wrong."""
    return rf"(?s)(^|[^\w.]){re.escape(arg)}\b.*\b(must|contains|is not|not a|got|missing|needs|beyond|outside|lies|disagrees|looks|unknown|lacks)\b"


def with_value(arg, v):
    """... and, for an overflow, quotes the value given (not a wrapped-around one)."""
    return rf"(?s)(?=.*(^|[^\w.]){re.escape(arg)}\b)(?=.*{re.escape(str(v))})"


def family(prefix, arg, call, values, skip=()):
    out = []
    for label, v, klass in values:
        if label in skip:
            continue
        match = with_value(arg, v[0] if isinstance(v, list) else v) if klass == "overflow" else names(arg)
        out.append(Case(f"{prefix}-{arg}-{label}", klass, (lambda v=v: call(v)), match=match))
    return out


def L():
    return _lptv()


# ------------------------------------------------------------------------------ the table

def python_cases():
    lp = L
    C = []

    # Model(a, b, w0, ts) and its constructors
    C += family("Model", "w0", lambda v: lp().Model([[1.0], [1.0]], [[1.0]], w0=v), FLOAT_BAD)
    C += family("Model", "ts", lambda v: lp().Model([[1.0], [1.0]], [[1.0]], w0=1.0, ts=v),
                [f for f in FLOAT_BAD if f[0] not in ("none", "zero")])
    C += [
        Case("Model-a-str", "type", lambda: lp().Model("abc", [[1.0]], 1.0), match=names("a")),
        Case("Model-a-none", "type", lambda: lp().Model(None, [[1.0]], 1.0), match=names("a")),
        Case("Model-a-3d", "shape", lambda: lp().Model(np.ones((2, 1, 1)), [[1.0]], 1.0), match=names("a")),
        Case("Model-a-nan", "nan/inf", lambda: lp().Model([[NaN], [1.0]], [[1.0]], 1.0), match=names("a")),
        Case("Model-b-inf", "nan/inf", lambda: lp().Model([[1.0], [1.0]], [[INF]], 1.0), match=names("b")),
        Case("Model-b-even", "shape", lambda: lp().Model([[1.0], [1.0]], np.ones((1, 2)), 1.0), match=names("b")),
        Case("Model-b-no-rows", "size", lambda: lp().Model([[1.0], [1.0]], np.zeros((0, 1)), 1.0), match=names("b")),
        Case("Model-w0-int", "value", lambda: lp().Model([[1.0], [1.0]], [[1.0]], 2),
             check=lambda m: m.w0 == 2.0),
        Case("Model-w0-0d-array", "value", lambda: lp().Model([[1.0], [1.0]], [[1.0]], np.array(0.5)),
             check=lambda m: m.w0 == 0.5),
        Case("Model-w0-1x1-array", "value", lambda: lp().Model([[1.0], [1.0]], [[1.0]], np.array([[0.5]])),
             check=lambda m: m.w0 == 0.5),
        Case("frozen-t-one-element-array", "value", lambda: lti().frozen(np.array([0.0])),
             check=lambda nd: np.allclose(nd[1], [1.0, 2.0]) and np.allclose(nd[0], [1.0])),
        Case("Model-ts-zero-is-continuous", "value", lambda: lp().Model([[1.0], [1.0]], [[1.0]], 1.0, ts=0),
             check=lambda m: m.ts is None),
        Case("from_tf-den-str", "type", lambda: lp().Model.from_tf([1.0], "abc"), match=names("den")),
        Case("from_tf-num-nan", "nan/inf", lambda: lp().Model.from_tf([NaN], [1.0, 1.0]), match=names("num")),
        Case("from_tf-w0-str", "type", lambda: lp().Model.from_tf([1.0], [1.0, 1.0], w0="x"), match=names("w0")),
        Case("from_tf-ts-negative", "range", lambda: lp().Model.from_tf([1.0], [1.0, 1.0], ts=-1.0), match=names("ts")),
    ]
    # Model methods
    C += family("freqresp", "branch", lambda v: lti().freqresp([1.0], branch=v),
                [f for f in INT_BAD if f[0] != "negative"])
    C += family("freqresp", "harmonics", lambda v: ltv().freqresp([1.0], harmonics=v),
                [f for f in INT_BAD if f[0] != "none"])
    C += [
        Case("freqresp-w-str", "type", lambda: lti().freqresp("abc"), match=names("w")),
        Case("freqresp-w-nan", "nan/inf", lambda: lti().freqresp([NaN]), match=names("w")),
        Case("freqresp-branch-beyond", "range", lambda: ltv().freqresp([1.0], branch=40, harmonics=4),
             match=names("branch")),
        Case("freqresp-lti-value", "value", lambda: lti().freqresp([2.0]),
             check=lambda H: np.allclose(H, 1 / (2j + 2), rtol=1e-14)),
        Case("a_at-t-str", "type", lambda: lti().a_at("abc"), match=names("t")),
        Case("b_at-t-2d", "shape", lambda: lti().b_at(np.zeros((2, 2))), match=names("t")),
        Case("frozen-t-nan", "nan/inf", lambda: lti().frozen(NaN), match=names("t")),
        Case("frozen-t-str", "type", lambda: lti().frozen("abc"), match=names("t")),
        Case("frozen-t-list", "shape", lambda: lti().frozen([0.0, 1.0]), match=names("t")),
        Case("to_tf-t-str", "type", lambda: ltv().to_tf("abc"), match=names("t")),
        Case("to_tf-t-inf", "nan/inf", lambda: ltv().to_tf(INF), match=names("t")),
        Case("to_tf-t-none-ltv", "value", lambda: ltv().to_tf(), match=r"^t: .*time-varying"),
        Case("to_lti-t-nan", "nan/inf", lambda: ltv().to_lti(NaN), match=names("t")),
    ]
    # Model persistence
    C += [
        Case("load-binary-junk", "file", lambda: lp().Model.load(write("junk.json", JUNK)), match=r"junk\.json.*JSON"),
        Case("load-not-json", "file", lambda: lp().Model.load(write("text.json", "hello")), match=r"text\.json.*JSON"),
        Case("load-npz-as-model", "file", lambda: lp().Model.load(good_npz()), match=r"good\.npz.*JSON"),
        Case("load-missing-file", "file", lambda: lp().Model.load(folder() / "none.json"), exc=OSError,
             match=r"none\.json"),
        Case("load-directory", "file", lambda: lp().Model.load(folder()), exc=ValueError, match=r"lptv-bad-inputs.*is a folder"),
        Case("load-path-none", "type", lambda: lp().Model.load(None), match=names("path")),
        Case("load-json-list", "file", lambda: lp().Model.load(write("list.json", "[1, 2]")), match=r"lptv\.Model"),
        Case("load-version-999", "file", lambda: lp().Model.load(model_json(version=999)), match=names("version")),
        Case("load-version-str", "file", lambda: lp().Model.load(model_json(version="1")), match=names("version")),
        Case("load-no-version", "file", lambda: lp().Model.load(model_json(version=_DROP)), match=r"version"),
        Case("load-w0-str", "file", lambda: lp().Model.load(model_json(w0="abc")), match=names("w0")),
        Case("load-w0-null", "file", lambda: lp().Model.load(model_json(w0=None)), match=names("w0")),
        Case("load-ts-negative", "file", lambda: lp().Model.load(model_json(ts=-1.0)), match=names("ts")),
        Case("load-a-real-str", "file", lambda: lp().Model.load(model_json(a_real="abc")), match=names("a_real")),
        Case("load-a-imag-shape", "file", lambda: lp().Model.load(model_json(a_imag=[[0.0, 0.0]])),
             match=names("a_imag")),
        Case("load-b-real-missing", "file", lambda: lp().Model.load(model_json(b_real=_DROP)), match=r"b_real"),
        Case("load-b-ragged", "file", lambda: lp().Model.load(model_json(b_real=[[1.0], [1.0, 2.0]])),
             match=names("b_real")),
        Case("load-covariance-str", "file",
             lambda: lp().Model.load(model_json(covariance="abc", eta_names=["a0.re0"])), match=names("covariance")),
        Case("load-covariance-nan", "file",
             lambda: lp().Model.load(write("cov.json", json.dumps(dict(lti().to_dict(), covariance=[[NaN]],
                                                                        eta_names=["a0.re0"])))),
             match=names("covariance")),
        Case("load-eta-names-number", "file",
             lambda: lp().Model.load(model_json(covariance=[[1.0]], eta_names=5)), match=names("eta_names")),
        Case("load-format-wrong", "file", lambda: lp().Model.load(model_json(format="other")), match=r"format"),
        Case("from_dict-not-dict", "type", lambda: lp().Model.from_dict("abc"), match=r"lptv\.Model"),
        Case("load-roundtrip", "value", lambda: lp().Model.load(model_json()), check=lambda m: m == lti()),
        Case("save-path-proc", "file", lambda: lti().save("/proc/nope/model.json"), exc=OSError, match=r"/proc/nope"),
        Case("save-path-none", "type", lambda: lti().save(None), match=names("path")),
    ]

    # multisine and friends
    C += family("multisine", "n_samples", lambda v: lp().multisine([1], v), INT_BAD)
    C += family("multisine", "lines", lambda v: lp().multisine(v, 16), [
        ("none", None, "type"), ("str", "abc", "type"), ("nan", [NaN], "nan/inf"), ("fraction", [1.5], "type"),
        ("2**31", [2**31], "overflow"), ("2**63", [2**63], "overflow"), ("-2**31", [-2**31], "overflow"),
        ("2d", [[1, 2]], "shape"), ("empty", [], "size"), ("repeated", [2, 2], "value")])
    C += family("multisine", "amplitudes", lambda v: lp().multisine([1, 2], 16, amplitudes=v), [
        ("str", "abc", "type"), ("nan", NaN, "nan/inf"), ("complex", [1j, 1.0], "type"),
        ("length", [1.0, 2.0, 3.0], "shape"), ("2d", np.ones((2, 1)), "shape")])
    C += family("multisine", "seed", lambda v: lp().multisine([1, 2], 16, seed=v), [
        ("str", "abc", "type"), ("negative", -1, "range"), ("fraction", 2.5, "type"), ("nan", NaN, "nan/inf")])
    C += [
        Case(f"multisine-dc-amplitude-seed{s}", "value", lambda: lp().multisine([0, 3], 16, amplitudes=2.0, seed=s),
             check=lambda ms: np.isclose(abs(np.mean(ms.signal)), 2.0, rtol=1e-14)
             and np.allclose(ms.signal, _cosines(ms), atol=1e-13))
        for s in range(3)]
    C += [
        Case(f"multisine-nyquist-amplitude-seed{s}", "value", lambda: lp().multisine([3, 8], 16, amplitudes=1.5, seed=s),
             check=lambda ms: np.isclose(abs(np.mean(ms.signal * (-1.0) ** np.arange(16))), 1.5, rtol=1e-14)
             and np.allclose(ms.signal, _cosines(ms), atol=1e-13))
        for s in range(3)]
    C += [
        Case("multisine-lines-object-ints", "value", lambda: lp().multisine(np.array([1, 3], dtype=object), 16, seed=0),
             check=lambda ms: ms.lines.tolist() == [1, 3] and np.allclose(np.abs(ms.spectrum[[1, 3]]), 0.5)),
        Case("multisine-nyquist-odd-N", "value", lambda: lp().multisine([7], 15, seed=4),
             check=lambda ms: np.isclose(np.max(np.abs(np.fft.rfft(ms.signal) / 15 * 2)), 1.0, rtol=1e-12)),
        Case("Multisine.periods-fraction", "type", lambda: lp().multisine([1], 8, seed=0).periods(2.5),
             match=names("P")),
        Case("Multisine.periods-str", "type", lambda: lp().multisine([1], 8, seed=0).periods("x"), match=names("P")),
        Case("Multisine.periods-zero", "range", lambda: lp().multisine([1], 8, seed=0).periods(0), match=names("P")),
        Case("Multisine.periods-2**63", "overflow", lambda: lp().multisine([1], 8, seed=0).periods(2**63),
             match=with_value("P", 2**63)),
        Case("Multisine.periods-value", "value", lambda: lp().multisine([1], 8, seed=0).periods(np.int64(3)),
             check=lambda x: x.shape == (3, 8)),
        Case("spectrum-x-str", "type", lambda: lp().spectrum("abc"), match=names("x")),
        Case("spectrum-x-2d", "shape", lambda: lp().spectrum(np.ones((2, 2))), match=names("x")),
        Case("spectrum-x-nan", "nan/inf", lambda: lp().spectrum([0.0, NaN]), match=names("x")),
        Case("spectrum-x-complex", "type", lambda: lp().spectrum([1j, 1.0]), match=names("x")),
    ]
    # noise variances moderated across lines
    def mod_fd(L=100):
        rng = np.random.default_rng(0)
        u = rng.standard_normal((4, 2 * L))
        return lp().FrequencyData.from_periods(u, 2 * u + 0.1 * rng.standard_normal((4, 2 * L)), w0=1.0)

    C += [
        Case("moderated_noise-data-array", "type", lambda: lp().moderated_noise(np.ones(10)), match=names("data")),
        Case("moderated_noise-half_width-zero", "range", lambda: lp().moderated_noise(mod_fd(), 0),
             match=names("half_width")),
        Case("moderated_noise-half_width-str", "type", lambda: lp().moderated_noise(mod_fd(), "3"),
             match=names("half_width")),
        Case("moderated_noise-half_width-2**63", "overflow", lambda: lp().moderated_noise(mod_fd(), 2**63),
             match=with_value("half_width", 2**63)),
        Case("moderated_noise-few-lines", "value", lambda: lp().moderated_noise(mod_fd(12)),
             check=lambda m: m.prior_dof == 0 and np.all(m.dof[1:-1] == 6)),
    ]
    # disturbances that are not periodic in the record
    def dist_uy(P=4, N=64):
        rng = np.random.default_rng(0)
        u = rng.standard_normal((P, N))
        return u, 2 * u + 0.1 * rng.standard_normal((P, N))

    C += [
        Case("disturbances-u-1d", "shape", lambda: lp().disturbances(np.ones(64), dist_uy()[1]), match=names("u")),
        Case("disturbances-y-str", "type", lambda: lp().disturbances(dist_uy()[0], "abc"), match=names("y")),
        Case("disturbances-y-nan", "nan/inf", lambda: lp().disturbances(dist_uy()[0], np.where(np.eye(4, 64) > 0, NaN, dist_uy()[1])),
             match=names("y")),
        Case("disturbances-shapes", "shape", lambda: lp().disturbances(dist_uy()[0], dist_uy()[1][:, :-1]),
             match=names("u and y")),
        Case("disturbances-one-period", "value", lambda: lp().disturbances(*[x[:1] for x in dist_uy()]), match=names("u")),
        Case("disturbances-alpha-zero", "range", lambda: lp().disturbances(*dist_uy(), alpha=0.0), match=names("alpha")),
        Case("disturbances-alpha-str", "type", lambda: lp().disturbances(*dist_uy(), alpha="x"), match=names("alpha")),
        Case("disturbances-max_count-negative", "range", lambda: lp().disturbances(*dist_uy(), max_count=-1),
             match=names("max_count")),
        Case("disturbances-max_count-2**63", "overflow", lambda: lp().disturbances(*dist_uy(), max_count=2**63),
             match=with_value("max_count", 2**63)),
        Case("disturbances-short-record", "value", lambda: lp().disturbances(*dist_uy(2, 8)),
             check=lambda out: out.found == ()),
    ]
    # what a record holds before any model (lptv.inspect)
    C += family("inspect", "fs", lambda v: lp().inspect(u=ins_record()[0], y=ins_record()[1], fs=v), FLOAT_BAD,
                skip=("none",))
    C += family("inspect", "dt", lambda v: lp().inspect(u=ins_record()[0], y=ins_record()[1], dt=v), FLOAT_BAD,
                skip=("none",))
    C += family("inspect", "reach", lambda v: lp().inspect(u=ins_record()[0], y=ins_record()[1], reach=v), INT_BAD,
                skip=("none",))
    C += [
        Case("inspect-y-missing", "type", lambda: lp().inspect(u=ins_record()[0]), match=names("y")),
        Case("inspect-u-str", "type", lambda: lp().inspect(u="abc", y=ins_record()[1]), match=names("u")),
        Case("inspect-u-complex", "type", lambda: lp().inspect(u=ins_record()[0] * 1j, y=ins_record()[1]),
             match=names("u")),
        Case("inspect-u-nan", "nan/inf", lambda: lp().inspect(u=np.where(np.arange(600) == 5, NaN, ins_record()[0]),
                                                              y=ins_record()[1]), match=names("u")),
        Case("inspect-y-length", "shape", lambda: lp().inspect(u=ins_record()[0], y=ins_record()[1][:-1]),
             match=names("y")),
        Case("inspect-short", "size", lambda: lp().inspect(u=np.ones(4), y=np.ones(4)), match="too few"),
        Case("inspect-dead-input", "value", lambda: lp().inspect(u=np.ones(600), y=ins_record()[1]),
             match="dead or disconnected input"),
        Case("inspect-fs-and-dt", "value", lambda: lp().inspect(u=ins_record()[0], y=ins_record()[1], fs=1.0, dt=1.0),
             match="not both"),
        Case("inspect-file-missing", "file", lambda: lp().inspect(folder() / "none.csv"), match="no such file"),
        Case("inspect-file-junk", "file", lambda: lp().inspect(write("junk.csv", JUNK)), match="text"),
        Case("inspect-file-input-missing", "file", lambda: lp().inspect(good_npz(), u="force"),
             match=r"'force', the input named by --input \(u=\), is missing"),
        Case("inspect-value", "value", lambda: lp().inspect(u=ins_record()[0], y=ins_record()[1], fs=10.0),
             check=lambda r: r.period_samples == 50 and r.period == 5.0 and r.lines.tolist() == [2, 5, 7]),
        Case("plots.inspection-insp-str", "type", lambda: _plots().inspection("abc"), match=names("insp")),
    ]
    # one record with its transient
    def rec():
        from lptv.examples import discrete_model, transient_record
        m = discrete_model()
        u, y = transient_record(m, periods=2, noise_std=0.01, seed=0)
        return m, u, y

    def rec_call(**kw):
        m, u, y = rec()
        args = dict(u=u, y=y, na=2, nb=1, ka=[2, 1, 0], kb=[2, 0], w0=m.w0, ts=1.0)
        args.update(kw)
        return lp().identify_record(args.pop("u"), args.pop("y"), **args)

    C += [
        Case("identify_record-u-str", "type", lambda: rec_call(u="abc"), match=names("u")),
        Case("identify_record-u-nan", "nan/inf", lambda: rec_call(u=np.full(512, NaN)), match=names("u")),
        Case("identify_record-y-length", "shape", lambda: rec_call(y=np.ones(300)), match=names("y")),
        Case("identify_record-u-not-whole-periods", "value",
             lambda: rec_call(u=np.ones(500), y=np.ones(500)), match=names("u")),
        Case("identify_record-ts-zero", "range", lambda: rec_call(ts=0.0), match=names("ts")),
        Case("identify_record-ts-str", "type", lambda: rec_call(ts="1"), match=names("ts")),
        Case("identify_record-w0-negative", "range", lambda: rec_call(w0=-1.0), match=names("w0")),
        Case("identify_record-noise-unknown", "value", lambda: rec_call(noise="flat"), match=names("noise")),
        Case("identify_record-noise-negative", "range", lambda: rec_call(noise=-1.0), match=names("noise")),
        Case("identify_record-lines-zero", "range", lambda: rec_call(lines=[0, 5]), match=names("lines")),
        Case("identify_record-u-zero", "value", lambda: rec_call(u=np.zeros(512)), match=names("u")),
        # the input's content on lines 200..250 of the record, the fit on lines 1..60 (and their +-2 L)
        Case("identify_record-u-not-excited-on-lines", "value",
             lambda: rec_call(u=_record_cosines(range(200, 251), 512), lines=range(1, 61)),
             match=r"^u: the input is not excited on the fitted lines"),
        Case("identify_record-ka-length", "shape", lambda: rec_call(ka=[1, 1]), match=names("ka")),
        Case("identify_record-na-zero", "range", lambda: rec_call(na=0), match=names("na")),
        Case("identify_record-max_iterations-zero", "range", lambda: rec_call(max_iterations=0),
             match=names("max_iterations")),
        Case("identify_record-value", "value", lambda: rec_call(),
             check=lambda r: r.converged and r.periods == 2 and 0.7 < r.cost_ratio < 1.3),
    ]
    # excitation design
    C += family("min_crest_multisine", "n_samples", lambda v: lp().min_crest_multisine([1, 2], v), INT_BAD)
    C += family("min_crest_multisine", "oversample", lambda v: lp().min_crest_multisine([1, 2], 16, oversample=v),
                INT_BAD + [("zero", 0, "range")], skip=("none",))
    C += family("min_crest_multisine", "max_p", lambda v: lp().min_crest_multisine([1, 2], 16, max_p=v),
                INT_BAD + [("three", 3, "range"), ("not-power-of-two", 24, "value")])
    C += family("min_crest_multisine", "iterations_per_p",
                lambda v: lp().min_crest_multisine([1, 2], 16, iterations_per_p=v), INT_BAD)
    C += [
        Case("min_crest_multisine-lines-repeated", "value", lambda: lp().min_crest_multisine([2, 2], 16),
             match=names("lines")),
        Case("min_crest_multisine-lines-range", "range", lambda: lp().min_crest_multisine([1, 9], 16),
             match=names("lines")),
        Case("min_crest_multisine-amplitudes-zero", "value",
             lambda: lp().min_crest_multisine([1, 2], 16, amplitudes=0.0), match=names("amplitudes")),
        Case("min_crest_multisine-amplitudes-nan", "nan/inf",
             lambda: lp().min_crest_multisine([1, 2], 16, amplitudes=[1.0, NaN]), match=names("amplitudes")),
        Case("min_crest_multisine-start-unknown", "value",
             lambda: lp().min_crest_multisine([1, 2], 16, start="clip"), match=names("start")),
        Case("min_crest_multisine-seed-with-schroeder", "value",
             lambda: lp().min_crest_multisine([1, 2], 16, seed=1), match=names("seed")),
        Case("min_crest_multisine-seed-str", "type",
             lambda: lp().min_crest_multisine([1, 2], 16, start="random", seed="x"), match=names("seed")),
        Case("min_crest_multisine-value", "value", lambda: lp().min_crest_multisine(range(1, 21), 256),
             check=lambda ms: ms.crest_factor < 1.6 and np.allclose(np.abs(ms.spectrum[1:21]), 0.5)),
        Case("schroeder_multisine-amplitudes-zero", "value",
             lambda: lp().schroeder_multisine([1, 2], 16, amplitudes=0.0), match=names("amplitudes")),
        Case("schroeder_multisine-lines-str", "type", lambda: lp().schroeder_multisine("abc", 16),
             match=names("lines")),
        Case("schroeder_multisine-value", "value", lambda: lp().schroeder_multisine(range(1, 51), 1024),
             check=lambda ms: 1.65 < ms.crest_factor < 1.8),
        Case("multisine_realisations-lines-empty", "size", lambda: lp().multisine_realisations([], 16, 2),
             match=names("lines")),
        Case("multisine_realisations-seed-str", "type",
             lambda: lp().multisine_realisations([1], 16, 2, seed="x"), match=names("seed")),
        Case("excitation_lines-kind-unknown", "value", lambda: lp().excitation_lines(1, 50, kind="even"),
             match=names("kind")),
        Case("excitation_lines-last-below-first", "range", lambda: lp().excitation_lines(50, 10),
             match=names("last")),
        Case("excitation_lines-group-one", "range", lambda: lp().excitation_lines(1, 50, group=1),
             match=names("group")),
        Case("excitation_lines-no-multiple", "value", lambda: lp().excitation_lines(1, 4, reach=3),
             match=names("reach")),
        Case("excitation_lines-value", "value", lambda: lp().excitation_lines(1, 30, kind="odd-odd"),
             check=lambda d: d.excited.tolist() == [1, 5, 9, 13, 17, 21, 25, 29]),
        Case("ExcitationLines.role-str", "type", lambda: lp().excitation_lines(1, 30).role("x"),
             match=names("line")),
        Case("CrestDesign-value", "value",
             lambda: lp().min_crest_multisine(range(1, 11), 64, return_design=True)[1],
             check=lambda d: isinstance(d, lp().CrestDesign) and d.crest_factor <= d.initial_crest_factor),
    ]
    C += family("multisine_realisations", "M", lambda v: lp().multisine_realisations([1, 2], 16, v),
                INT_BAD + [("zero", 0, "range")])
    C += family("excitation_lines", "reach", lambda v: lp().excitation_lines(1, 50, reach=v), INT_BAD)
    C += family("excitation_lines", "first", lambda v: lp().excitation_lines(v, 50), INT_BAD + [("zero", 0, "range")])
    C += family("time_signal", "n_samples", lambda v: lp().time_signal([1.0, 0.5], v), INT_BAD)
    C += [
        Case("time_signal-X-str", "type", lambda: lp().time_signal("abc", 8), match=names("X")),
        Case("time_signal-X-2d", "shape", lambda: lp().time_signal(np.ones((2, 2)), 8), match=names("X")),
        Case("time_signal-X-complex-dc", "value", lambda: lp().time_signal([1j, 1.0], 8), match=names("X")),
        Case("time_signal-X-too-long", "size", lambda: lp().time_signal(np.ones(6), 8), match=names("X")),
    ]

    # simulate, htf, band_matrices
    C += family("simulate", "lines_out", lambda v: lp().simulate(lti(), [1.0, 1.0], lines_out=v),
                [f for f in INT_BAD if f[0] != "none"])
    C += family("simulate", "guard", lambda v: lp().simulate(lti(), [1.0, 1.0], guard=v),
                [f for f in INT_BAD if f[0] != "none"])
    C += family("simulate", "max_guard", lambda v: lp().simulate(ltv(), [1.0, 1.0], max_guard=v), INT_BAD,
                skip=("negative", "none"))
    C += family("simulate", "tol", lambda v: lp().simulate(lti(), [1.0, 1.0], tol=v), FLOAT_BAD)
    C += family("simulate", "solver", lambda v: lp().simulate(lti(), [1.0, 1.0], solver=v),
                [("none", None, "type"), ("bogus", "lu", "value"), ("number", 3, "type")])
    C += family("simulate", "full_output", lambda v: lp().simulate(lti(), [1.0, 1.0], full_output=v),
                [("str", "yes", "type"), ("nan", NaN, "nan/inf"), ("list", [1], "type")])
    C += [
        Case("simulate-model-str", "type", lambda: lp().simulate("model", [1.0, 1.0]), match=names("model")),
        Case("simulate-model-none", "type", lambda: lp().simulate(None, [1.0, 1.0]), match=names("model")),
        Case("simulate-U-str", "type", lambda: lp().simulate(lti(), "abc"), match=names("U")),
        Case("simulate-U-none", "type", lambda: lp().simulate(lti(), None), match=names("U")),
        Case("simulate-U-3d", "shape", lambda: lp().simulate(lti(), np.ones((2, 2, 2))), match=names("U")),
        Case("simulate-U-empty", "size", lambda: lp().simulate(lti(), []), match=names("U")),
        Case("simulate-U-nan", "nan/inf", lambda: lp().simulate(lti(), [1.0, NaN]), match=names("U")),
        Case("simulate-U-complex-dc", "value", lambda: lp().simulate(lti(), [1j, 1.0]), match=names("U")),
        Case("simulate-lti-value", "value", lambda: lp().simulate(lti(), [0.0, 0.5]),
             check=lambda Y: np.isclose(Y[1], 0.5 / (0.1j + 2), rtol=1e-13)),
        Case("simulate-max_guard-too-small-warns", "value", lambda: lp().simulate(
            _modulated(), [0.0, 0.5, 0.2, 0.1], max_guard=2, tol=1e-15, full_output=True),
            warning="TruncationWarning",
            check=lambda r: np.abs(r.Y - lp().simulate(_modulated(), [0.0, 0.5, 0.2, 0.1], tol=1e-15, max_guard=400)).max()
            <= r.truncation_error * np.abs(r.Y).max()),
        Case("simulate-lines_out-beyond-dt", "range", lambda: lp().simulate(dt_model(), np.ones(3), lines_out=5),
             match=names("lines_out")),
    ]
    C += family("htf", "L", lambda v: lp().htf(lti(), v, [0]), INT_BAD)
    C += family("htf", "lines", lambda v: lp().htf(lti(), 3, v), [
        ("str", "abc", "type"), ("none-entry", [None], "type"), ("fraction", [0.5], "type"),
        ("2**31", [2**31], "overflow"), ("2**63", [2**63], "overflow"), ("-2**31", [-2**31], "overflow"),
        ("beyond", [5], "range"), ("int", 3, "type")])
    C += [Case("htf-model-str", "type", lambda: lp().htf("m", 3), match=names("model")),
          Case("htf-solver-bogus", "value", lambda: lp().htf(lti(), 3, solver="dense"), match=names("solver"))]
    C += family("band_matrices", "L", lambda v: lp().band_matrices(lti(), v), INT_BAD)
    C += [Case("band_matrices-model-none", "type", lambda: lp().band_matrices(None), match=names("model"))]

    # FrequencyData
    def fd(**kw):
        args = dict(U=[1.0, 0.5, 0.5], Y=[1.0, 0.5, 0.5], varU=[0.0] * 3, varY=[1e-2] * 3, w0=1.0)
        args.update(kw)
        return lp().FrequencyData(args.pop("U"), args.pop("Y"), args.pop("varU"), args.pop("varY"), **args)

    C += family("FrequencyData", "periods", lambda v: fd(periods=v), INT_BAD + [("one", 1, "range")])

    # correlated_lines: data from periods, a probability
    def periods_data():
        rng = np.random.default_rng(0)
        return lp().FrequencyData.from_periods(rng.standard_normal((4, 64)), rng.standard_normal((4, 64)), w0=1.0)

    C += family("correlated_lines", "alpha", lambda v: lp().correlated_lines(periods_data(), alpha=v),
                FLOAT_BAD + [("one", 1.0, "range")])
    C += [Case("correlated_lines-d-none", "type", lambda: lp().correlated_lines(None), match=names("d")),
          Case("correlated_lines-d-given", "value", lambda: lp().correlated_lines(fd(periods=4)), match=names("d")),
          Case("FrequencyData.from_periods-statistics-bad", "value",
               lambda: lp().FrequencyData.from_periods(np.ones((2, 8)), np.ones((2, 8)), w0=1.0, statistics="lines"),
               match=names("statistics"))]
    C += family("FrequencyData", "w0", lambda v: fd(w0=v), FLOAT_BAD)
    C += family("FrequencyData", "ts", lambda v: fd(ts=v), [f for f in FLOAT_BAD if f[0] != "none"])
    C += [
        Case("FrequencyData-U-complex-dc", "value", lambda: fd(U=[1j, 0.5, 0.5]), match=names("U")),
        Case("FrequencyData-Y-complex-dc", "value", lambda: fd(Y=[1j, 0.5, 0.5]), match=names("Y")),
        Case("FrequencyData-U-2d", "shape", lambda: fd(U=np.ones((3, 1))), match=names("U")),
        Case("FrequencyData-U-str", "type", lambda: fd(U="abc"), match=names("U")),
        Case("FrequencyData-U-none", "type", lambda: fd(U=None), match=names("U")),
        Case("FrequencyData-U-nan", "nan/inf", lambda: fd(U=[1.0, NaN, 0.5]), match=names("U")),
        Case("FrequencyData-U-empty", "size", lambda: fd(U=[], Y=[], varU=[], varY=[]), match=names("U")),
        Case("FrequencyData-Y-length", "shape", lambda: fd(Y=[1.0, 0.5]), match=names("Y")),
        Case("FrequencyData-varY-negative", "range", lambda: fd(varY=[-1.0] * 3), match=names("varY")),
        Case("FrequencyData-varU-complex", "type", lambda: fd(varU=[1j] * 3), match=names("varU")),
        Case("FrequencyData-covYU-str", "type", lambda: fd(covYU="abc"), match=names("covYU")),
        Case("FrequencyData-covYU-too-large", "range", lambda: fd(varU=[1.0] * 3, covYU=[0, 0, 2.0]),
             match=names("covYU")),
        Case("FrequencyData-periods-0-value", "value", lambda: fd(periods=0), check=lambda d: d.periods == 0),
        Case("FrequencyData-periods-np-int", "value", lambda: fd(periods=np.int32(5)), check=lambda d: d.periods == 5),
    ]
    C += family("from_periods", "w0", lambda v: lp().FrequencyData.from_periods(U(), Y(), w0=v), FLOAT_BAD)
    C += family("from_periods", "ts", lambda v: lp().FrequencyData.from_periods(U(), Y(), w0=0.1, ts=v),
                [f for f in FLOAT_BAD if f[0] != "none"])
    C += [
        Case("from_periods-u-str", "type", lambda: lp().FrequencyData.from_periods("abc", Y(), w0=0.1),
             match=names("u")),
        Case("from_periods-u-1d", "shape", lambda: lp().FrequencyData.from_periods(U()[0], Y()[0], w0=0.1),
             match=names("u")),
        Case("from_periods-u-complex", "type", lambda: lp().FrequencyData.from_periods(U() * 1j, Y(), w0=0.1),
             match=names("u")),
        Case("from_periods-y-nan", "nan/inf", lambda: lp().FrequencyData.from_periods(U(), Y() * NaN, w0=0.1),
             match=names("y")),
        Case("from_periods-one-period", "size", lambda: lp().FrequencyData.from_periods(U()[:1], Y()[:1], w0=0.1),
             match=names("u")),
        Case("from_periods-transposed", "shape", lambda: lp().FrequencyData.from_periods(U().T, Y().T, w0=0.1),
             match=r"(?s)\bu\b.*transposed"),
        # more periods than samples is not by itself a transposed record
        Case("from_periods-many-short-periods", "value", lambda: lp().FrequencyData.from_periods(
            lp().multisine([1, 2], 8, seed=0).periods(100) + 1e-3 * np.random.default_rng(0).standard_normal((100, 8)),
            lp().multisine([1, 2], 8, seed=0).periods(100), w0=1.0),
             check=lambda d: d.periods == 100 and np.isclose(abs(d.U[1]), 0.5, rtol=1e-3)),
        Case("from_periods-many-noise-periods", "value", lambda: lp().FrequencyData.from_periods(
            np.random.default_rng(0).standard_normal((1000, 4)), np.random.default_rng(1).standard_normal((1000, 4)),
            w0=1.0), check=lambda d: d.periods == 1000),
        Case("from_periods-shape-mismatch", "shape",
             lambda: lp().FrequencyData.from_periods(U(), Y()[:, :128], w0=0.1), match=names("u and y")),
    ]

    # identify
    def ident(**kw):
        args = dict(na=1, nb=0, w0=0.1)
        args.update(kw)
        return lp().identify(U(), Y(), **args)

    C += family("identify", "na", lambda v: ident(na=v), INT_BAD)
    C += family("identify", "nb", lambda v: ident(nb=v), INT_BAD)
    C += family("identify", "ka", lambda v: ident(ka=v), [f for f in INT_BAD if f[0] != "list"])
    C += family("identify", "kb", lambda v: ident(kb=v), [f for f in INT_BAD if f[0] != "list"])
    C += family("identify", "max_iter", lambda v: ident(max_iter=v), INT_BAD)
    C += family("identify", "tol", lambda v: ident(tol=v), FLOAT_BAD)
    C += family("identify", "w0", lambda v: ident(w0=v), [f for f in FLOAT_BAD if f[0] != "none"])
    C += family("identify", "ts", lambda v: ident(ts=v), [f for f in FLOAT_BAD if f[0] != "none"])
    C += family("identify", "method", lambda v: ident(method=v), [("none", None, "type"), ("bogus", "ml", "value"),
                                                                  ("number", 1, "type")])
    C += family("identify", "lines", lambda v: ident(lines=v), [
        ("str", "abc", "type"), ("none-entry", [None, 3], "type"), ("fraction", [1.5, 3], "type"),
        ("nan", [NaN, 3], "nan/inf"), ("2**31", [2**31, 3], "overflow"), ("2**63", [2**63, 3], "overflow"),
        ("-2**31", [-2**31, 3], "overflow"), ("beyond", [5, 500], "range"), ("empty", [], "size"),
        ("2d", [[3, 4]], "shape"), ("int", 3, "type")])
    C += family("identify", "known", lambda v: ident(known=v), [
        ("str", "a1", "type"), ("bad-name", {"q1": 1.0}, "value"), ("nan", {"a1": NaN}, "nan/inf"),
        ("str-value", {"a1": "x"}, "type"), ("beyond", {"a5": 1.0}, "range")])
    C += [
        Case("identify-u-str", "type", lambda: lp().identify("abc", Y(), na=1, nb=0, w0=0.1), match=names("u")),
        Case("identify-U-str", "type", lambda: lp().identify(U().astype(str), Y(), na=1, nb=0, w0=0.1),
             match=names("u")),
        Case("identify-y-missing", "type", lambda: lp().identify(U(), na=1, nb=0, w0=0.1), match=names("y")),
        Case("identify-w0-missing", "type", lambda: lp().identify(U(), Y(), na=1, nb=0), match=names("w0")),
        Case("identify-ka-list-length", "shape", lambda: ident(ka=[1, 2, 3]), match=names("ka")),
        Case("identify-transient-bogus", "value", lambda: ident(transient="yes"), match=names("transient")),
        Case("identify-transient-one-channel", "value", lambda: ident(transient=True), match=names("transient")),
        Case("identify-ka-list-2**31", "overflow", lambda: ident(ka=[2**31, 0]), match=with_value("ka", 2**31)),
        Case("identify-ka-list-nan", "nan/inf", lambda: ident(ka=[NaN, 0]), match=names("ka")),
        Case("identify-data-w0-disagrees", "value", lambda: lp().identify(data(), na=1, nb=0, w0=0.2),
             match=names("w0")),
        Case("identify-transposed", "shape", lambda: lp().identify(U().T, Y().T, na=1, nb=0, w0=0.1),
             match=r"transposed"),
        Case("identify-value", "value", lambda: ident(na=np.int64(1), nb=0.0, tol=np.float32(1e-8)),
             check=lambda r: np.allclose(r.model.a[:, 0].real, [2.0, 1.0], atol=1e-2)),
    ]
    C += family("IdentificationResult.confidence_interval", "level", lambda v: fit().confidence_interval(v),
                FLOAT_BAD + [("one", 1.0, "range")])

    # crb, htf_estimate, floquet, select
    def crb(**kw):
        args = dict(var_y=1e-4)
        args.update(kw)
        return lp().crb(lti(), args.pop("u", lp().multisine(range(1, 20), 64, seed=0)), **args)

    C += family("crb", "var_y", lambda v: crb(var_y=v), [("str", "abc", "type"), ("nan", NaN, "nan/inf"),
                                                        ("negative", -1.0, "range"), ("shape", [1.0, 2.0], "shape"),
                                                        ("none", None, "type")])
    C += family("crb", "periods", lambda v: crb(periods=v), INT_BAD)
    C += family("crb", "lines", lambda v: crb(lines=v), [("str", "abc", "type"), ("2**31", [2**31], "overflow"),
                                                        ("beyond", [1000], "range")])
    C += [Case("crb-model-str", "type", lambda: lp().crb("m", [0.0, 1.0], var_y=1.0), match=names("model")),
          Case("crb-u-str", "type", lambda: crb(u="abc"), match=names("u")),
          Case("crb-cov_yu-too-large", "range", lambda: crb(var_u=1e-4, cov_yu=1.0), match=names("cov_yu"))]

    def htfe(**kw):
        return lp().htf_estimate(U(), Y(), **dict(dict(w0=0.1), **kw))

    C += family("htf_estimate", "branches", lambda v: htfe(branches=v), INT_BAD)
    C += family("htf_estimate", "degree", lambda v: htfe(method="lpm", degree=v), INT_BAD)
    C += family("htf_estimate", "width", lambda v: htfe(method="lpm", width=v), [f for f in INT_BAD if f[0] != "none"])
    C += family("htf_estimate", "w0", lambda v: htfe(w0=v), FLOAT_BAD)
    C += family("htf_estimate", "excited", lambda v: htfe(excited=v), [
        ("str", "abc", "type"), ("2**31", [2**31], "overflow"), ("zero", [0], "range"), ("fraction", [1.5], "type")])
    C += [Case("htf_estimate-method", "value", lambda: htfe(method="x"), match=names("method")),
          Case("HtfEstimate.branch-k-str", "type", lambda: htfe().branch("x"), match=names("k")),
          Case("HtfEstimate.significant-alpha-nan", "nan/inf", lambda: htfe().significant(NaN), match=names("alpha"))]

    @functools.lru_cache(maxsize=1)
    def realisations():
        """3 random-phase realisations x 2 periods of a first-order system, lines 3, 6, 9, 12."""
        m = lp().Model([[2.0], [1.0]], [[1.0]], w0=1.0)
        rng = np.random.default_rng(5)
        u, y = [], []
        for r in range(3):
            ms = lp().multisine([3, 6, 9, 12], 64, seed=r)
            y0 = lp().time_signal(lp().simulate(m, ms.spectrum), 64)
            u.append(np.tile(ms.signal, (2, 1)) + 1e-3 * rng.standard_normal((2, 64)))
            y.append(np.tile(y0, (2, 1)) + 1e-3 * rng.standard_normal((2, 64)))
        return np.array(u), np.array(y)

    def dist(**kw):
        u, y = realisations()
        return lp().distortion(kw.pop("u", u), kw.pop("y", y), **{"w0": 1.0, **kw})

    C += family("distortion", "w0", lambda v: dist(w0=v), FLOAT_BAD)
    C += family("distortion", "ratio", lambda v: dist(ratio=v), FLOAT_BAD)
    C += family("distortion", "branches", lambda v: dist(branches=v), [f for f in INT_BAD if f[0] != "none"])
    C += [Case("distortion-u-2d", "shape", lambda: dist(u=np.zeros((2, 64))), match=names("u")),
          Case("distortion-u-one-realisation", "size", lambda: dist(u=realisations()[0][:1], y=realisations()[1][:1]),
               match=names("u")),
          Case("distortion-y-nan", "nan/inf", lambda: dist(y=np.full((3, 2, 64), NaN)), match=names("y")),
          Case("distortion-y-shape", "shape", lambda: dist(y=realisations()[1][:, :, :32]), match=r"same shape"),
          Case("DistortionResult.nonlinear_smooth-width-str", "type", lambda: dist().nonlinear_smooth("x"),
               match=names("width")),
          Case("DistortionResult.experiments-width-negative", "range", lambda: dist().experiments(-1),
               match=names("width")),
          Case("DistortionResult.lack_of_fit-model-str", "type", lambda: dist().lack_of_fit("m"),
               match=names("model")),
          Case("DistortionResult.experiments-referred-bogus", "value", lambda: dist().experiments(referred="in"),
               match=names("referred")),
          Case("DistortionResult.experiments-referred-input-no-model", "value",
               lambda: dist().experiments(referred="input"), match=names("model")),
          Case("DistortionResult.input_level-model-str", "type", lambda: dist().input_level("m"), match=names("model")),
          Case("DistortionResult.lack_of_fit-model-other-w0", "range",
               lambda: dist().lack_of_fit(lp().Model([[2.0], [1.0]], [[1.0]], w0=2.0)), match=names("model")),
          Case("DistortionResult.lack_of_fit-lines-beyond", "range",
               lambda: dist().lack_of_fit(lp().Model([[2.0], [1.0]], [[1.0]], w0=1.0), lines=[3, 10**6]),
               match=names("lines")),
          Case("DistortionResult.lack_of_fit-lines-nan", "nan/inf",
               lambda: dist().lack_of_fit(lp().Model([[2.0], [1.0]], [[1.0]], w0=1.0), lines=[3.0, NaN]),
               match=names("lines")),
          Case("DistortionResult.lack_of_fit-lines-str", "type",
               lambda: dist().lack_of_fit(lp().Model([[2.0], [1.0]], [[1.0]], w0=1.0), lines="abc"),
               match=names("lines")),
          Case("DistortionResult.lack_of_fit-three-realisations", "value",
               lambda: dist().lack_of_fit(lp().Model([[2.0], [1.0]], [[1.0]], w0=1.0)),
               check=lambda r: r.permutations == 6 and not r.can_reject and not r.rejects),
          Case("identify-covariance-bogus", "value", lambda: lp().identify(*periods(), na=1, nb=0, w0=0.1,
               covariance="jackknife"), match=names("covariance")),
          Case("identify-bootstrap-5", "range", lambda: lp().identify(*periods(), na=1, nb=0, w0=0.1,
               covariance="bootstrap", bootstrap=5), match=names("bootstrap")),
          Case("identify-noise-bogus", "value", lambda: lp().identify(*periods(), na=1, nb=0, w0=0.1,
               noise="smoothed"), match=names("noise")),
          Case("identify-noise-int", "type", lambda: lp().identify(*periods(), na=1, nb=0, w0=0.1,
               noise=1), match=names("noise")),
          Case("identify-noise-moderated-bootstrap", "value", lambda: lp().identify(*periods(), na=1, nb=0, w0=0.1,
               noise="moderated", covariance="bootstrap"), match=names("noise")),
          Case("identify-disturbances-bogus", "value", lambda: lp().identify(*periods(), na=1, nb=0, w0=0.1,
               disturbances="subtract"), match=names("disturbances")),
          Case("identify-disturbances-true", "type", lambda: lp().identify(*periods(), na=1, nb=0, w0=0.1,
               disturbances=True), match=names("disturbances")),
          Case("identify-disturbances-frequency-data", "value", lambda: lp().identify(
               lp().FrequencyData.from_periods(*periods(), w0=0.1), na=1, nb=0, disturbances="remove"),
               match=names("disturbances"))]

    C += family("floquet", "tol", lambda v: lp().floquet(ltv(), tol=v), FLOAT_BAD)
    C += family("floquet", "min_truncation", lambda v: lp().floquet(ltv(), min_truncation=v), INT_BAD)
    C += family("floquet", "max_truncation", lambda v: lp().floquet(ltv(), max_truncation=v), INT_BAD)
    C += [Case("floquet-model-str", "type", lambda: lp().floquet("m"), match=names("model"))]

    def sel(**kw):
        args = dict(na=1, nb=0, k=0, w0=0.1, executor="serial")
        args.update(kw)
        return lp().select(U(), Y(), **args)

    C += family("select", "na", lambda v: sel(na=v), [f for f in INT_BAD if f[0] != "list"])
    C += family("select", "k", lambda v: sel(k=v), [f for f in INT_BAD if f[0] not in ("list", "none")])
    C += family("select", "refine", lambda v: sel(refine=v), INT_BAD)
    C += family("select", "alpha", lambda v: sel(alpha=v), FLOAT_BAD)
    C += [Case("select-criterion", "value", lambda: sel(criterion="bic"), match=names("criterion")),
          Case("select-executor", "value", lambda: sel(executor="nowhere"), match=names("executor")),
          Case("select-workers", "range", lambda: sel(executor="processes", workers=0), match=names("workers"))]

    # validation
    C += family("expected_fraction_above_0db", "n_rows", lambda v: lp().expected_fraction_above_0db(v, 3, 4),
                INT_BAD)
    C += family("expected_fraction_above_0db", "n_free", lambda v: lp().expected_fraction_above_0db(100, v, 4),
                INT_BAD)
    C += family("expected_fraction_above_0db", "periods", lambda v: lp().expected_fraction_above_0db(100, 3, v),
                INT_BAD)
    C += [
        Case("expected_fraction-n_rows-zero", "range", lambda: lp().expected_fraction_above_0db(0, 3, 4),
             match=names("n_rows")),
        Case("expected_fraction-n_free-above-rows", "range", lambda: lp().expected_fraction_above_0db(10, 30, 4),
             match=names("n_free")),
        Case("expected_fraction-value", "value", lambda: lp().expected_fraction_above_0db(1000, 0, 0),
             check=lambda r: np.isclose(r[0], np.exp(-1.0), rtol=1e-12)),
        Case("normalized_residue-model-none", "type", lambda: lp().normalized_residue(None, data(), [3, 4]),
             match=names("model")),
        Case("normalized_residue-data-str", "type", lambda: lp().normalized_residue(lti(), "abc", [3, 4]),
             match=names("data")),
        Case("normalized_residue-lines-str", "type", lambda: lp().normalized_residue(lti(), data(), "abc"),
             match=names("lines")),
        Case("normalized_residue-lines-2**63", "overflow",
             lambda: lp().normalized_residue(lti(), data(), [2**63]), match=with_value("lines", 2**63)),
        Case("normalized_residue-lines-beyond", "range", lambda: lp().normalized_residue(lti(), data(), [500]),
             match=names("lines")),
        Case("frozen_poles-model-str", "type", lambda: lp().frozen_poles("m", [0.0]), match=names("model")),
        Case("frozen_poles-t-nan", "nan/inf", lambda: lp().frozen_poles(lti(), [NaN]), match=names("t")),
        Case("frozen_zeros-t-str", "type", lambda: lp().frozen_zeros(lti(), "abc"), match=names("t")),
    ]

    # measurements
    def rm(name, content, *a, **kw):
        return lp().read_measurements(write(name, content), *a, **kw)

    u, y = (U, Y)
    C += family("read_measurements", "periods", lambda v: lp().read_measurements(good_npz(), v),
                [f for f in INT_BAD if f[0] != "none"] + [("zero", 0, "range")])
    C += family("read_measurements", "fs", lambda v: lp().read_measurements(good_npz(), fs=v),
                [f for f in FLOAT_BAD if f[0] != "none"])
    C += family("read_measurements", "period", lambda v: lp().read_measurements(good_npz(), fs=1.0, period=v),
                [f for f in FLOAT_BAD if f[0] != "none"])
    C += family("read_measurements", "skip-periods", lambda v: lp().read_measurements(good_npz(), skip_periods=v),
                INT_BAD)
    C += [
        Case("read_measurements-path-none", "type", lambda: lp().read_measurements(None), match=names("path")),
        Case("read_measurements-path-int", "type", lambda: lp().read_measurements(3), match=names("path")),
        Case("read_measurements-missing", "file", lambda: lp().read_measurements(folder() / "none.npz"),
             match=r"no such file"),
        Case("read_measurements-trim-str", "type", lambda: lp().read_measurements(good_npz(), trim="no"),
             match=names("trim")),
        Case("read-csv-binary", "file", lambda: rm("junk.csv", JUNK, 4), match=r"not a text file"),
        Case("read-npz-binary", "file", lambda: rm("junk.npz", JUNK), match=r"cannot read as NPZ"),
        Case("read-mat-binary", "file", lambda: rm("junk.mat", JUNK), match=r"cannot read as a MATLAB file"),
        Case("read-npz-truncated", "file", lambda: rm("cut.npz", good_npz().read_bytes()[:300]), match=r"cannot read as NPZ"),
        Case("read-npz-wrong-keys", "file", lambda: rm("keys.npz", {"input": u(), "output": y()}),
             match=r"'u' is missing"),
        Case("read-mat-wrong-keys", "file", lambda: rm("keys.mat", {"x": u()}), match=r"'u' is missing"),
        Case("read-npz-transposed", "file", lambda: rm("t.npz", {"u": u().T, "y": y().T}),
             match=r"'u'.*transposed"),
        Case("read-mat-transposed", "file", lambda: rm("t.mat", {"u": u().T, "y": y().T}),
             match=r"'u'.*transposed"),
        Case("read-csv-transposed", "file",
             lambda: rm("t.csv", "u,y\n" + "\n".join(f"{a},{b}" for a, b in zip(u().ravel(), y().ravel())), 256),
             match=r"'u'.*transposed.*--periods"),
        Case("read-npz-w0-str", "file", lambda: rm("w0.npz", {"u": u(), "y": y(), "w0": "abc"}), match=r"w0"),
        Case("read-npz-u-str", "file", lambda: rm("s.npz", {"u": u().astype(str), "y": y()}), match=r"'u'"),
        Case("read-csv-empty", "file", lambda: rm("e.csv", "", 4), match=r"empty"),
        Case("read-json-ext", "file", lambda: rm("m.json", "{}"), match=r"unknown file type '\.json'"),
        Case("read_measurements-u-int", "type", lambda: lp().read_measurements(good_npz(), u=3), match=names("u")),
        Case("read_measurements-u-empty", "value", lambda: lp().read_measurements(good_npz(), u=" "), match=names("u")),
        Case("read_measurements-u-missing", "file", lambda: lp().read_measurements(good_npz(), u="force"),
             match=names("u")),
        Case("read_measurements-y-two", "shape", lambda: lp().read_measurements(good_npz(), y=["y", "u"]),
             match=names("y")),
        Case("read_measurements-y-comma", "shape", lambda: lp().read_measurements(good_npz(), y="y,w0"),
             match=names("y")),
        Case("read_measurements-time-list", "type", lambda: lp().read_measurements(good_npz(), time=[1.0]),
             match=names("time")),
        Case("read_measurements-time-missing", "file", lambda: lp().read_measurements(good_npz(), time="t"),
             match=names("time")),
        Case("read-csv-time-not-uniform", "file",
             lambda: rm("jitter.csv", "t,u,y\n" + "\n".join(f"{k + (k > 5) * 0.5},{a},{b}" for k, (a, b)
                                                            in enumerate(zip(u().ravel(), y().ravel()))), period=256.0),
             match=r"'t' is not uniformly sampled: sample 7 \(line 8\)"),
        Case("read-npz-fs-negative", "file", lambda: rm("fs.npz", {"u": u().ravel(), "y": y().ravel(), "fs": -1.0},
                                                        period=25.6), match=r"'fs' must be a positive scalar"),
        Case("read-npz-named-value", "value",
             lambda: rm("named.npz", {"force": u().ravel(), "disp": y().ravel(), "dt": 0.1}, u="force", y="disp",
                        period=25.6),
             check=lambda m: m.u.shape == (4, 256) and np.array_equal(m.u, U()) and m.fs == 10.0),
        Case("read-npz-value", "value", lambda: lp().read_measurements(good_npz()),
             check=lambda m: m.u.shape == (4, 256) and np.array_equal(m.u, U()) and m.w0 == 0.1),
    ]
    C += family("check_record", "spread_limit", lambda v: lp().check_record(U(), Y(), spread_limit=v), FLOAT_BAD)
    C += [Case("check_record-u-str", "type", lambda: lp().check_record("abc", Y()), match=names("u")),
          Case("check_record-warn-str", "type", lambda: lp().check_record(U(), Y(), warn="no"), match=names("warn")),
          Case("check_record-transposed", "shape", lambda: lp().check_record(U().T, Y().T), match=r"transposed")]

    # parameters
    C += family("parameter_table", "level", lambda v: lp().parameter_table(fit(), v), FLOAT_BAD)
    C += family("lti_table", "level", lambda v: lp().lti_table(fit(), v), FLOAT_BAD)
    C += family("freqresp_band", "level", lambda v: lp().freqresp_band(fit(), [1.0], level=v), FLOAT_BAD)
    C += [
        Case("parameter_table-obj-str", "type", lambda: lp().parameter_table("abc"), match=names("obj")),
        Case("lti_table-obj-none", "type", lambda: lp().lti_table(None), match=names("obj")),
        Case("freqresp_band-w-str", "type", lambda: lp().freqresp_band(fit(), "abc"), match=names("w")),
        Case("freqresp_band-branch-str", "type", lambda: lp().freqresp_band(fit(), [1.0], branch="x"),
             match=names("branch")),
        Case("compare-obj-str", "type", lambda: lp().compare("abc", U(), Y()), match=names("obj")),
        Case("compare-u-str", "type", lambda: lp().compare(fit(), "abc", Y()), match=names("u")),
        Case("compare-y-nan", "nan/inf", lambda: lp().compare(fit(), U(), Y() * NaN), match=names("y")),
        Case("compare-shape", "shape", lambda: lp().compare(fit(), U(), Y()[:, :100]), match=names("u and y")),
        Case("predict-model-str", "type", lambda: lp().predict("abc", U()[0], fs=1.0), match=names("model")),
        Case("predict-u-nan", "nan/inf", lambda: lp().predict(fit().model, U()[0] * NaN, fs=1.0), match=names("u")),
        Case("predict-u-short", "size", lambda: lp().predict(fit().model, U()[0][:1], fs=1.0), match=names("u")),
        Case("predict-fs-negative", "range", lambda: lp().predict(fit().model, U()[0], fs=-1.0), match=names("fs")),
        Case("predict-initial-str", "type", lambda: lp().predict(fit().model, U()[0], fs=1.0, initial="warm"),
             match=names("initial")),
        Case("validate-model-str", "type", lambda: lp().validate("abc", U(), Y()), match=names("model")),
        Case("validate-y-nan", "nan/inf", lambda: lp().validate(fit().model, U(), Y() * NaN), match=names("y")),
        Case("validate-shape", "shape", lambda: lp().validate(fit().model, U(), Y()[:, :100]),
             match=names("u and y")),
    ]

    # batch
    def many(**kw):
        args = dict(na=1, nb=0, w0=0.1, executor="serial", progress=False)
        args.update(kw)
        return lp().identify_many(args.pop("records", [(U(), Y())]), **args)

    C += family("identify_many", "na", lambda v: many(na=v), [f for f in INT_BAD if f[0] != "list"])
    C += family("identify_many", "tol", lambda v: many(tol=v), FLOAT_BAD)
    C += family("identify_many", "chunk_size", lambda v: many(chunk_size=v),
                [f for f in INT_BAD if f[0] not in ("none", "2**31", "2**63")])
    C += [Case("identify_many-records-str", "type", lambda: many(records="abc.npz"), match=names("records")),
          Case("identify_many-records-int", "type", lambda: many(records=5), match=names("records")),
          Case("identify_many-method", "value", lambda: many(method="ml"), match=names("method")),
          Case("identify_many-ka-str", "type", lambda: many(ka="x"), match=names("ka")),
          Case("identify_many-names-length", "shape", lambda: many(names=["a", "b"]), match=names("names")),
          Case("identify_many-executor", "value", lambda: many(executor="nowhere"), match=names("executor")),
          Case("identify_many-read-str", "type", lambda: many(read="abc"), match=names("read")),
          Case("identify_many-read-key", "value", lambda: many(read={"channel": "u"}), match=names("read")),
          Case("identify_many-read-periods", "value", lambda: many(read={"periods": 4}), match=names("read")),
          Case("identify_many-read-fs", "range", lambda: many(read={"fs": -1.0}), match=names("read")),
          Case("identify_many-read-u", "type", lambda: many(read={"u": 3}), match=names("read")),
          Case("identify_many-checkpoint-int", "type", lambda: many(checkpoint=3), match=names("checkpoint"))]

    def mc(**kw):
        args = dict(periods=4, runs=1, snr_in_db=40.0, snr_out_db=40.0, executor="serial", progress=False)
        args.update(kw)
        return lp().montecarlo(lti(), args.pop("excitation", lp().multisine(range(1, 20), 64, seed=0)), **args)

    C += family("montecarlo", "runs", lambda v: mc(runs=v), INT_BAD)
    C += family("montecarlo", "periods", lambda v: mc(periods=v), INT_BAD)
    C += family("montecarlo", "snr_in_db", lambda v: mc(snr_in_db=v), [("str", "abc", "type"), ("nan", NaN, "nan/inf"),
                                                                     ("none", None, "type")])
    C += family("montecarlo", "pole_in", lambda v: mc(pole_in=v), [("str", "abc", "type"), ("nan", NaN, "nan/inf"),
                                                                 ("one", 1.0, "range")])
    C += family("montecarlo", "correlation", lambda v: mc(correlation=v), [("nan", NaN, "nan/inf"), ("two", 2.0, "range")])
    C += family("montecarlo", "level", lambda v: mc(level=v), FLOAT_BAD)
    C += family("montecarlo", "seed", lambda v: mc(seed=v), [("str", "abc", "type"), ("negative", -1, "range")])
    C += [Case("montecarlo-model-str", "type", lambda: lp().montecarlo("m", [0.0] * 8, periods=4, runs=1,
                                                                        snr_in_db=40, snr_out_db=40),
               match=names("model")),
          Case("montecarlo-excitation-str", "type", lambda: mc(excitation="abc"), match=names("excitation")),
          Case("montecarlo-methods", "value", lambda: mc(methods="ml"), match=names("methods")),
          # more than any memory budget holds: refused before the seeds are listed or a record is made
          Case("montecarlo-runs-beyond-memory", "size", lambda: mc(runs=2**31 - 1), match=names("runs")),
          Case("montecarlo-periods-beyond-memory", "size", lambda: mc(periods=10**9), match=names("periods")),
          Case("montecarlo-checkpoint-int", "type", lambda: mc(checkpoint=3), match=names("checkpoint")),
          Case("montecarlo-checkpoint-file", "file", lambda: mc(checkpoint=write("a-file", "text")),
               match=names("checkpoint"))]

    # results' methods and plots (matplotlib, the 'plots' extra)
    C += [
        Case("MonteCarloResult.save-format", "value", lambda: mc().save(folder() / "mc", format="xls"),
             match=names("format")),
        Case("MonteCarloResult.save-directory-none", "type", lambda: mc().save(None), match=names("directory")),
        Case("BatchResult.save-path", "file", lambda: many().save(folder() / "table.txt"), match=names("path")),
        Case("SelectionResult.summary-top", "range", lambda: sel().summary(top=0), match=names("top")),
        Case("plots.bode-res-str", "type", lambda: _plots().bode("abc"), match=names("res")),
        Case("plots.bode-n_points-zero", "range", lambda: _plots().bode(fit(), n_points=0), match=names("n_points")),
        Case("plots.bode-level-nan", "nan/inf", lambda: _plots().bode(fit(), level=NaN), match=names("level")),
        Case("plots.normalized_residue-r-str", "type", lambda: _plots().normalized_residue([1, 2], "ab"),
             match=names("r")),
        Case("plots.normalized_residue-length", "shape", lambda: _plots().normalized_residue([1, 2], [1.0]),
             match=names("r")),
        Case("plots.model_fit-Y-str", "type", lambda: _plots().model_fit([1, 2], "ab", [1.0, 1.0]),
             match=names("Y")),
        Case("plots.coefficients-t-str", "type", lambda: _plots().coefficients("abc", est=np.ones((3, 2))),
             match=names("t")),
        Case("plots.frozen_poles_zeros-t-str", "type", lambda: _plots().frozen_poles_zeros("abc"), match=names("t")),
        Case("plots.frozen_poles_zeros-poles-rows", "shape",
             lambda: _plots().frozen_poles_zeros([0.0, 1.0], poles_est=np.zeros((3, 2))), match=names("poles_est")),
        Case("plots.htf_branches-est-str", "type", lambda: _plots().htf_branches("abc"), match=names("est")),
        Case("plots.compare-cmp-str", "type", lambda: _plots().compare("abc"), match=names("cmp")),
        Case("plots.lack_of_fit-lof-str", "type", lambda: _plots().lack_of_fit("abc"), match=names("lof")),
        Case("plots.output_spectrum-w0-nan", "nan/inf", lambda: _plots().output_spectrum([1, 2], [1.0, 1.0], w0=NaN),
             match=names("w0")),
    ]

    # several inputs and outputs: MimoModel, simulate on it, mimo_multisines
    def mimo(a=None, b=None, w0=1.0, ts=None):
        a = np.stack([np.diag([2.0, 3.0]), np.eye(2)]) if a is None else a
        return lp().MimoModel(a, np.ones((1, 2, 1)) if b is None else b, w0=w0, ts=ts)

    C += family("MimoModel", "w0", lambda v: mimo(w0=v), FLOAT_BAD)
    C += [
        Case("MimoModel-a-str", "type", lambda: mimo(a="abc"), match=names("a")),
        Case("MimoModel-a-none", "type", lambda: lp().MimoModel(None, np.ones((1, 2, 1)), w0=1.0), match=names("a")),
        Case("MimoModel-a-2d", "shape", lambda: mimo(a=np.ones((2, 2))), match=names("a")),
        Case("MimoModel-a-not-square", "shape", lambda: mimo(a=np.ones((2, 2, 3, 1))), match=names("a")),
        Case("MimoModel-a-nan", "nan/inf", lambda: mimo(a=np.full((2, 2, 2), NaN)), match=names("a")),
        Case("MimoModel-a-even", "shape", lambda: mimo(a=np.ones((2, 2, 2, 2))), match=names("a")),
        Case("MimoModel-a-empty", "size", lambda: mimo(a=np.ones((0, 2, 2, 1))), match=names("a")),
        Case("MimoModel-b-none", "type", lambda: lp().MimoModel(np.ones((2, 2, 2)), None, w0=1.0), match=names("b")),
        Case("MimoModel-b-rows", "shape", lambda: mimo(b=np.ones((1, 3, 1))), match=names("b")),
        Case("MimoModel-b-inf", "nan/inf", lambda: mimo(b=np.full((1, 2, 1), INF)), match=names("b")),
        Case("MimoModel-from_dict-not-dict", "type", lambda: lp().MimoModel.from_dict("abc"),
             match=r"lptv\.MimoModel"),
        Case("MimoModel-load-siso", "file", lambda: lp().MimoModel.load(model_json()), match=r"lptv\.Model\.load"),
        Case("MimoModel-save-roundtrip", "value",
             lambda: (mimo().save(folder() / "mimo.json"), lp().MimoModel.load(folder() / "mimo.json"))[1],
             check=lambda m: m == mimo()),
        Case("MimoModel-ts-zero-is-continuous", "value", lambda: mimo(ts=0), check=lambda m: m.ts is None),
        Case("simulate-mimo-U-inputs", "shape", lambda: lp().simulate(mimo(), np.ones((4, 2))), match=names("U")),
        Case("simulate-mimo-U-str", "type", lambda: lp().simulate(mimo(), "abc"), match=names("U")),
        Case("simulate-mimo-U-nan", "nan/inf", lambda: lp().simulate(mimo(), np.full((4, 1), NaN)), match=names("U")),
        Case("simulate-mimo-solver", "value", lambda: lp().simulate(mimo(), np.ones((4, 1)), solver="x"),
             match=names("solver")),
        Case("simulate-mimo-lti", "value", lambda: lp().simulate(mimo(), np.array([[0.0], [1.0]])),
             check=lambda Y: np.allclose(Y[1], np.linalg.solve(np.diag([2.0, 3.0]) + 1j * np.eye(2), [1.0, 1.0]))),
    ]
    zero_row = np.zeros((2, 2, 2))
    zero_row[1, 0, 0] = zero_row[0, 0, 0] = 1.0                 # row 1 of A holds nothing
    C += [
        Case("floquet-mimo-tol", "range", lambda: lp().floquet(mimo(), tol=-1.0), match=names("tol")),
        Case("floquet-mimo-zero-row", "value", lambda: lp().floquet(mimo(a=zero_row)), match=names("a")),
        Case("floquet-mimo-lti", "value", lambda: lp().floquet(mimo()),
             check=lambda f: np.allclose(np.sort(f.exponents.real), [-3.0, -2.0], rtol=1e-10)),
        Case("frozen_poles-mimo-t-nan", "nan/inf", lambda: lp().frozen_poles(mimo(), [NaN]), match=names("t")),
        Case("frozen_poles-mimo-zero-row", "value", lambda: lp().frozen_poles(mimo(a=zero_row), [0.0]),
             match=names("model")),
        Case("monodromy-mimo-steps", "range",
             lambda: importlib.import_module("lptv.model.floquet").monodromy(mimo(), steps=0), match=names("steps")),
        Case("read_measurements-u-list-int", "type",
             lambda: lp().read_measurements(good_npz(), u=["u", 3], y=["y", "w0"]), match=names("u")),
        Case("read_measurements-y-list-empty", "size", lambda: lp().read_measurements(good_npz(), y=[]),
             match=names("y")),
        Case("read_measurements-several-twice", "value",
             lambda: lp().read_measurements(good_npz(), u=["u", "y"], y=["y"]), match=names("y")),
    ]
    C += family("mimo_multisines", "n_inputs", lambda v: lp().mimo_multisines([1, 2], 16, v), INT_BAD)
    C += family("mimo_multisines", "n_samples", lambda v: lp().mimo_multisines([1], v, 2), INT_BAD)
    C += [
        Case("mimo_multisines-design", "value", lambda: lp().mimo_multisines([1, 2], 16, 2, design="x"),
             match=names("design")),
        Case("mimo_multisines-n_experiments-few", "range",
             lambda: lp().mimo_multisines([1, 2], 16, 2, n_experiments=1), match=names("n_experiments")),
        Case("mimo_multisines-lines-repeated", "value", lambda: lp().mimo_multisines([2, 2], 16, 2), match=names("lines")),
        Case("mimo_multisines-amplitudes-shape", "shape",
             lambda: lp().mimo_multisines([1, 2], 16, 2, amplitudes=np.ones((3, 2))), match=names("amplitudes")),
        Case("mimo_multisines-dc-complex-pattern", "value", lambda: lp().mimo_multisines([0, 2], 16, 3),
             match=r"DC and the Nyquist line"),
        Case("mimo_htf_estimate-u-3d", "shape", lambda: lp().mimo_htf_estimate(np.ones((2, 4, 2)), np.ones((2, 4, 2)),
                                                                              [1], 0), match=names("u")),
        Case("mimo_htf_estimate-y-nan", "nan/inf",
             lambda: lp().mimo_htf_estimate(np.ones((2, 2, 8, 2)), np.full((2, 2, 8, 1), NaN), [1], 0), match=names("y")),
        Case("mimo_htf_estimate-lines-close", "value",
             lambda: lp().mimo_htf_estimate(np.ones((2, 2, 16, 2)), np.ones((2, 2, 16, 1)), [2, 3], 1),
             match=names("lines")),
        Case("mimo_htf_estimate-K-negative", "range",
             lambda: lp().mimo_htf_estimate(np.ones((2, 2, 16, 2)), np.ones((2, 2, 16, 1)), [2], -1), match=names("K")),
        Case("mimo_multisines-input_matrix-line", "range",
             lambda: lp().mimo_multisines([1, 2], 16, 2, seed=0).input_matrix(9), match=names("line")),
        # the MIMO estimators: data, identify on (P, N, channels) arrays, the CRB
        Case("MimoFrequencyData.from_periods-u-2d", "shape",
             lambda: lp().MimoFrequencyData.from_periods(np.ones((4, 16)), np.ones((4, 16, 2)), w0=1.0),
             match=names("u")),
        Case("MimoFrequencyData.from_periods-y-periods", "shape",
             lambda: lp().MimoFrequencyData.from_periods(np.ones((4, 16, 1)), np.ones((3, 16, 2)), w0=1.0),
             match=names("y")),
        Case("MimoFrequencyData.from_periods-u-one-period", "size",
             lambda: lp().MimoFrequencyData.from_periods(np.ones((1, 16, 1)), np.ones((1, 16, 2)), w0=1.0),
             match=names("u")),
        Case("MimoFrequencyData.from_periods-y-nan", "nan/inf",
             lambda: lp().MimoFrequencyData.from_periods(np.ones((4, 16, 1)), np.full((4, 16, 2), NaN), w0=1.0),
             match=names("y")),
        Case("MimoFrequencyData.from_periods-w0-zero", "range",
             lambda: lp().MimoFrequencyData.from_periods(np.ones((4, 16, 1)), np.ones((4, 16, 2)), w0=0.0),
             match=names("w0")),
        Case("identify-mimo-ka-shape", "shape",
             lambda: lp().identify(np.ones((4, 32, 1)), np.ones((4, 32, 2)), na=1, nb=0, w0=1.0, ka=np.ones((3, 3))),
             match=names("ka")),
        Case("identify-mimo-method", "value",
             lambda: lp().identify(np.ones((4, 32, 1)), np.ones((4, 32, 2)), na=1, nb=0, w0=1.0, method="ls"),
             match=names("method")),
        Case("mimo_crb-model-siso", "type", lambda: lp().mimo_crb(lti(), np.ones((9, 1)), noise=[1.0, 1.0], periods=4),
             match=names("model")),
        Case("mimo_crb-inputs-channels", "shape",
             lambda: lp().mimo_crb(mimo(), np.ones((9, 2)), noise=[1.0, 1.0, 1.0], periods=4), match=names("inputs")),
        Case("mimo_crb-noise-shape", "shape",
             lambda: lp().mimo_crb(mimo(), np.ones((9, 1)), noise=[1.0, 1.0], periods=4), match=names("noise")),
        Case("mimo_crb-noise-negative", "range",
             lambda: lp().mimo_crb(mimo(), np.ones((9, 1)), noise=[1.0, -1.0, 1.0], periods=4), match=names("noise")),
        Case("mimo_crb-periods-zero", "range",
             lambda: lp().mimo_crb(mimo(), np.ones((9, 1)), noise=[1.0, 1.0, 1.0], periods=0), match=names("periods")),
    ]
    return C


def _modulated():
    """An LPTV model whose output lines need a few guard lines to converge."""
    return _lptv().Model([[0.3j, 1, -0.3j], [0, 1, 0]], [[1.0]], w0=1.0)


def _plots():
    import matplotlib

    matplotlib.use("Agg")
    from lptv import plots

    return plots


def _cosines(ms):
    n = np.arange(ms.n_samples)
    return sum(A * np.cos(2 * np.pi * ((l * n) % ms.n_samples) / ms.n_samples + p)
               for l, A, p in zip(ms.lines, ms.amplitudes, ms.phases))


def _record_cosines(lines, n_samples, seed=0):
    """Cosines on lines of a record's own DFT grid (periodic in the record: no leakage to others)."""
    phases = np.random.default_rng(seed).uniform(0, 2 * np.pi, len(lines))
    n = np.arange(n_samples)
    return sum(np.cos(2 * np.pi * ((l * n) % n_samples) / n_samples + p) for l, p in zip(lines, phases))


# ---------------------------------------------------------------------- command-line cases

def cli_files(d: Path):
    """The files the command-line cases read, written into d."""
    u, y = periods()
    np.savez(d / "good.npz", u=u, y=y, w0=0.1)
    np.savez(d / "transposed.npz", u=u.T, y=y.T, w0=0.1)
    np.savez(d / "keys.npz", input=u, output=y)
    (d / "cut.npz").write_bytes((d / "good.npz").read_bytes()[:300])
    for ext in ("csv", "mat", "npz.json", "json"):
        (d / f"junk.{ext}").write_bytes(JUNK)
    (d / "text.json").write_text("hello")
    (d / "v999.json").write_text(json.dumps(dict(lti().to_dict(), version=999)))
    (d / "model.json").write_text(json.dumps(lti().to_dict()))
    (d / "dir.npz").mkdir(exist_ok=True)
    # one record of 8 periods of 64 samples whose input lies above the continuous fit's lines (1..63)
    y = np.random.default_rng(1).standard_normal(512)
    np.savetxt(d / "high.csv", np.c_[np.arange(512) / 64.0, _record_cosines(range(120, 250), 512), y],
               delimiter=",", header="t,u,y", comments="")


def cli_cases():
    ok = ("identify", "{dir}/good.npz", "--na", "1", "--nb", "0")
    sel = ("select", "{dir}/good.npz", "--na", "1", "--nb", "0", "--k", "0", "--workers", "1")
    mc = ("montecarlo", "--runs", "1", "--periods", "4", "--workers", "1", "--out", "{dir}/mc")
    demo = ("demo", "--out", "{dir}/demo")
    big = ("99999999999", "2147483648", "-2147483648")
    table = []

    def add(name, argv, opt):
        table.append(Case(f"cli-{name}", "cli", argv=tuple(argv), match=opt if opt.startswith("(") else re.escape(opt)))

    # lptv identify
    for f in ("junk.csv", "junk.mat", "junk.json", "cut.npz", "keys.npz", "transposed.npz", "dir.npz", "none.npz"):
        add(f"identify-file-{f}", ("identify", "{dir}/" + f, "--na", "1", "--nb", "0", "--periods", "4"), f)
    for v in ("-1", "abc", "2.5") + big:
        add(f"identify-na-{v}", ("identify", "{dir}/good.npz", "--na", v, "--nb", "0"), "--na")
    for v in ("-1", "abc"):
        add(f"identify-nb-{v}", ("identify", "{dir}/good.npz", "--na", "1", "--nb", v), "--nb")
    # too many parameters for the data: the message speaks of the orders and the equations
    add("identify-na-100000", ("identify", "{dir}/good.npz", "--na", "100000", "--nb", "0"),
        r"(?=.*free parameters)(?=.*orders)")
    add("identify-nb-100000", ("identify", "{dir}/good.npz", "--na", "1", "--nb", "100000"),
        r"(?=.*free parameters)(?=.*orders)")
    for v in ("-1", "abc", "1,2,3", "1,x") + big:
        add(f"identify-ka-{v}", ok + ("--ka", v), "--ka")
    for v in ("-1", "abc"):
        add(f"identify-kb-{v}", ok + ("--kb", v), "--kb")
    for opt in ("--w0", "--period", "--fs", "--dt", "--ts", "--tol"):
        for v in ("nan", "inf", "-1", "0", "abc"):
            add(f"identify-{opt[2:]}-{v}", ok + (opt, v), opt)
    for v in ("0", "-1", "abc", "3") + big:
        add(f"identify-periods-{v}", ok + ("--periods", v), "--periods")
    for v in ("-1", "abc", "3") + big:
        add(f"identify-skip-periods-{v}", ok + ("--skip-periods", v), "--skip-periods")
    for v in ("1-99999999999", "abc", "5-1", "1-500", "0-3", "2147483648"):
        add(f"identify-lines-{v}", ok + ("--lines", v), "--lines")
    for v in ("-1", "abc") + big:
        add(f"identify-max-iter-{v}", ok + ("--max-iter", v), "--max-iter")
    for v in ("abc", "a1=nan", "a9=1", "q1=1", "a1=1,a1=2"):
        add(f"identify-known-{v}", ok + ("--known", v), "--known")
    for v in ("abc", "b0", "b0=0", "b0=nan", "b9=1", "q1=1", "b0=x"):
        add(f"identify-scale-{v}", ok + ("--scale", v), "--scale")
    add("identify-scale-with-known", ok + ("--scale", "b0=1", "--known", "b0=1"), "--scale")
    for v in ("nan", "inf", "-1", "0", "abc"):
        add(f"identify-input-noise-{v}", ok + ("--one-record", "--period", "1", "--input-noise", v), "--input-noise")
    add("identify-input-noise-periods", ok + ("--input-noise", "0.1"), "--input-noise")
    add("identify-one-record-not-excited", ("identify", "{dir}/high.csv", "--one-record", "--period", "1", "--na", "1",
                                            "--nb", "0", "--out", "{dir}/high"), "u: the input is not excited")
    add("identify-method-bogus", ok + ("--method", "ml"), "--method")
    add("identify-covariance-bogus", ok + ("--covariance", "jackknife"), "--covariance")
    add("identify-noise-bogus", ok + ("--noise", "smooth"), "--noise")
    add("identify-referred-bogus", ok + ("--referred", "inside"), "--referred")
    add("identify-transient-bogus", ok + ("--transient", "yes"), "--transient")
    add("identify-transient-on-one-channel", ok + ("--transient", "on"), "--transient on is built for several channels")
    for v in ("5", "abc") + big:
        add(f"identify-bootstrap-{v}", ok + ("--bootstrap", v), "--bootstrap")
    add("identify-out-proc", ok + ("--out", "/proc/nope"), "/proc/nope")
    add("identify-workers-0", ok + ("--workers", "0"), "--workers")
    add("identify-workers-abc", ok + ("--workers", "abc"), "--workers")
    add("identify-discrete-without-fs", ok + ("--discrete",), "--discrete")
    add("identify-discrete-with-ts", ok + ("--discrete", "--ts", "0.1"), "--discrete")
    add("identify-scheduler-not-an-address", ok + ("--scheduler", "not an address"), "(scheduler|executor|dask)")
    add("identify-unknown-option", ok + ("--nope", "1"), "--nope")
    add("identify-input-missing", ok + ("--input", "force"), "--input")
    add("identify-reference-missing", ok + ("--reference", "r"), "--reference")
    add("identify-output-missing", ok + ("--output", "disp"), "--output")
    add("identify-output-two", ok + ("--output", "y,u"), "--output")
    add("identify-outputs-missing", ok + ("--output", "y,force"), "--output")
    add("identify-outputs-empty-name", ok + ("--output", "y,"), "--output")
    add("identify-outputs-known", ok + ("--output", "y,w0", "--known", "a1=1"), "--known")
    add("identify-outputs-scale", ok + ("--output", "y,w0", "--scale", "b0=0"), "--scale")
    add("identify-time-missing", ok + ("--time", "clock"), "--time")
    add("identify-resume-one-file", ok + ("--resume",), "--resume")
    add("identify-resume-nothing", ok + ("--workers", "1", "--out", "{dir}/batch", "--resume"), "--resume")
    add("identify-na-missing", ("identify", "{dir}/good.npz", "--nb", "0"), "--na")
    # lptv inspect
    ins = ("inspect", "{dir}/good.npz", "--out", "{dir}/inspect")
    for f in ("junk.csv", "junk.mat", "cut.npz", "dir.npz", "none.npz"):
        add(f"inspect-file-{f}", ("inspect", "{dir}/" + f), f)
    for opt in ("--fs", "--dt"):
        for v in ("nan", "inf", "-1", "0", "abc"):
            add(f"inspect-{opt[2:]}-{v}", ins + (opt, v), opt)
    for v in ("0", "-1", "abc") + big:
        add(f"inspect-reach-{v}", ins + ("--reach", v), "--reach")
    add("inspect-input-missing", ins + ("--input", "force"), "--input")
    add("inspect-output-missing", ins + ("--output", "disp"), "--output")
    add("inspect-reference-missing", ins + ("--reference", "r"), "--reference")
    add("inspect-reference-two-inputs", ins + ("--input", "u,y", "--reference", "u"), "--reference")
    add("inspect-time-missing", ins + ("--time", "clock"), "--time")
    add("inspect-out-proc", ins[:2] + ("--out", "/proc/nope"), "/proc/nope")
    add("inspect-unknown-option", ins + ("--nope", "1"), "--nope")
    # lptv select
    add("select-file-junk", ("select", "{dir}/junk.csv", "--periods", "4"), "junk.csv")
    add("select-file-transposed", ("select", "{dir}/transposed.npz"), "transposed")
    for opt, vals in (("--na", ("abc", "5-1", "1-99999999999", "-1")), ("--nb", ("abc",)),
                      ("--k", ("99999999999", "abc", "1-2147483648"))):
        for v in vals:
            argv = list(sel)
            argv[argv.index(opt) + 1] = v
            add(f"select-{opt[2:]}-{v}", argv, opt)
    for opt in ("--w0", "--period", "--ts", "--fs", "--dt"):
        for v in ("nan", "-1", "abc"):
            add(f"select-{opt[2:]}-{v}", sel + (opt, v), opt)
    for v in ("-1", "abc", "3") + big:
        add(f"select-skip-periods-{v}", sel + ("--skip-periods", v), "--skip-periods")
    for v in ("-1", "abc", "2147483648"):
        add(f"select-refine-{v}", sel + ("--refine", v), "--refine")
    add("select-periods-0", sel + ("--periods", "0"), "--periods")
    add("select-lines-huge", sel + ("--lines", "1-99999999999"), "--lines")
    add("select-criterion-bogus", sel + ("--criterion", "bic"), "--criterion")
    add("select-workers-0", ("select", "{dir}/good.npz", "--workers", "0"), "--workers")
    add("select-scheduler-not-an-address", sel[:-2] + ("--scheduler", "not an address"), "(scheduler|executor|dask)")
    add("select-out-proc", sel + ("--out", "/proc/nope"), "/proc/nope")
    add("select-input-missing", sel + ("--input", "force"), "--input")
    add("select-output-two", sel + ("--output", "y,u"), "--output")
    add("select-time-missing", sel + ("--time", "clock"), "--time")
    # lptv montecarlo
    for opt, vals in (("--runs", ("0", "-1", "abc", "2147483648")), ("--periods", ("1", "abc", "2147483648")),
                      ("--samples", ("0", "-1", "99999999999")), ("--snr-in", ("nan", "abc")),
                      ("--snr-out", ("nan",)), ("--pole-in", ("1", "nan", "abc")), ("--pole-out", ("-1",)),
                      ("--correlation", ("2", "nan")), ("--seed", ("-1", "abc")), ("--multisine-seed", ("-1",)),
                      ("--chunk-size", ("0", "-1")), ("--lines", ("abc", "1-99999999999")),
                      ("--method", ("ml", "wgtls,wgtls")), ("--format", ("xls",)), ("--workers", ("0",))):
        for v in vals:
            argv = list(mc)
            if opt in argv:
                argv[argv.index(opt) + 1] = v
            else:
                argv += [opt, v]
            if opt == "--samples":
                argv += ["--model", "{dir}/model.json", "--excited", "1-10"]
            # lptv.montecarlo's own message names its argument 'methods', which --method sets
            add(f"montecarlo-{opt[2:]}-{v}", argv, r"(\bmethods?\b)" if opt == "--method" else opt)
    for f in ("none.json", "junk.json", "text.json", "v999.json"):
        add(f"montecarlo-model-{f}", mc + ("--model", "{dir}/" + f, "--excited", "1-10"), f)
    add("montecarlo-excited-huge", mc + ("--model", "{dir}/model.json", "--excited", "1-99999999999"), "--excited")
    add("montecarlo-excited-without-model", mc + ("--excited", "1-10"), "--excited")
    add("montecarlo-runs-beyond-memory", ("montecarlo", "--runs", "2147483647", "--periods", "4", "--workers", "1",
                                          "--out", "{dir}/mc"), "--runs")
    add("montecarlo-periods-beyond-memory", ("montecarlo", "--runs", "1", "--periods", "1000000000", "--workers", "1",
                                             "--out", "{dir}/mc"), "--periods")
    add("montecarlo-scheduler-not-an-address", mc[:5] + ("--scheduler", "not an address"),
        "(scheduler|executor|dask)")
    add("montecarlo-resume-nothing", mc + ("--resume",), "--resume")
    add("montecarlo-out-proc", ("montecarlo", "--runs", "1", "--workers", "1", "--out", "/proc/nope"), "/proc/nope")
    # lptv demo
    add("demo-out-proc", ("demo", "--quick", "--out", "/proc/nope"), "/proc/nope")
    add("demo-lecture-out-proc", ("demo", "lecture", "--quick", "--out", "/proc/nope"), "/proc/nope")
    for opt, vals in (("--monte-carlo", ("-1", "abc", "2147483648")), ("--periods", ("1", "-1", "abc", "2147483648")),
                      ("--seed", ("-1", "abc", "2.5"))):
        for v in vals:
            add(f"demo-{opt[2:]}-{v}", demo + (opt, v), opt)
    add("demo-case-bogus", ("demo", "nope"), "nope")
    add("no-command", ("nope",), "nope")
    return table


def all_cases():
    return python_cases() + cli_cases()
