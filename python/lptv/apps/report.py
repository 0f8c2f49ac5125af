"""A small offline HTML report: headings, text, tables and figures (PNG files embedded)."""
from __future__ import annotations

import base64
import html
import io
import json
import os
from pathlib import Path

import numpy as np

from lptv.atomic import atomic_open, staged_folder
from lptv.use.modelfile import context_of


class Report:
    """Collects the pieces of a report and writes ``report.html`` plus the figures as PNG.

    Examples
    --------
    >>> import tempfile, lptv
    >>> from lptv.apps.report import Report
    >>> r = Report("Example")
    >>> r.paragraph("One table.")
    >>> r.table(["a", "b"], [[1, 2.5]])
    >>> d = tempfile.mkdtemp(); r.write(d).name
    'report.html'
    """

    def __init__(self, title: str):
        self.title = title
        self._parts = []
        self._figures = []

    def heading(self, text: str, level: int = 2):
        self._parts.append(f"<h{level}>{html.escape(text)}</h{level}>")

    def paragraph(self, text: str):
        self._parts.append(f"<p>{html.escape(text)}</p>")

    def verdict(self, text: str, ok: bool):
        """The verdict, first thing on the page: green when the model is consistent with the data."""
        self._parts.append(f'<p class="verdict {"ok" if ok else "bad"}"><b>Verdict:</b> {html.escape(text)}.</p>')

    def preformatted(self, text: str):
        self._parts.append(f"<pre>{html.escape(text)}</pre>")

    def table(self, header, rows):
        def fmt(v):
            if isinstance(v, (bool, np.bool_)):
                return str(bool(v))
            if isinstance(v, (float, np.floating)):
                return f"{float(v):.4g}"
            if isinstance(v, (int, np.integer)):
                return str(int(v))
            if isinstance(v, (list, tuple, np.ndarray)):
                return "[" + ", ".join(fmt(x) for x in v) + "]"
            return str(v)
        head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
        body = "".join("<tr>" + "".join(f"<td>{html.escape(fmt(v))}</td>" for v in row) + "</tr>"
                       for row in rows)
        self._parts.append(f"<table><tr>{head}</tr>{body}</table>")

    def figure(self, fig, filename: str, caption: str):
        """Adds a matplotlib figure, saved as ``filename`` (PNG) and embedded in the page."""
        buf = io.BytesIO()
        # Agg straight to PNG at a light compression (a third of the encoding time of zlib's default)
        fig.savefig(buf, format="png", dpi=110, pil_kwargs={"compress_level": 2})
        data = buf.getvalue()
        self._figures.append((filename, data))
        b64 = base64.b64encode(data).decode("ascii")
        self._parts.append(
            f'<figure><img alt="{html.escape(filename)}" src="data:image/png;base64,{b64}">'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>")

    def write(self, out_dir) -> Path:
        out = Path(os.fspath(out_dir))
        out.mkdir(parents=True, exist_ok=True)
        for name, data in self._figures:
            with atomic_open(out / name, "wb") as f:
                f.write(data)
        style = ("body{font-family:sans-serif;max-width:60em;margin:2em auto;padding:0 1em;color:#222}"
                 "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:.2em .6em;"
                 "text-align:right}td:first-child{text-align:left}th{background:#eee}figure{margin:1.5em 0}img{max-width:100%}"
                 "figcaption{font-size:.92em;color:#444}pre{background:#f6f6f6;padding:.6em;white-space:pre-wrap}"
                 ".verdict{padding:.6em .8em;border-left:.4em solid}.ok{background:#eef8ee;border-color:#3a3}"
                 ".bad{background:#fcefee;border-color:#c33}")
        page = (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(self.title)}"
                f"</title><style>{style}</style></head><body><h1>{html.escape(self.title)}</h1>"
                + "\n".join(self._parts) + "</body></html>")
        path = out / "report.html"
        with atomic_open(path, encoding="utf-8") as f:
            f.write(page)
        return path


def write_json(path, obj):
    """JSON with NumPy scalars turned into Python numbers."""
    def conv(o):
        if isinstance(o, np.generic):
            return o.item()
        if isinstance(o, np.ndarray):
            return o.tolist()
        raise TypeError(f"not JSON serialisable: {type(o).__name__}")

    with atomic_open(os.fspath(path)) as f:
        json.dump(obj, f, indent=1, default=conv)


PLOTS_EXTRA = "writing report.html needs matplotlib, an optional extra: pip install 'lptv[plots]'"


FIT_FILES = ("model.json", "summary.json", "report.html")
"""The files of a fit that a later fit into the same folder replaces (or removes)."""


def write_fit(out, model, summary, report):
    """Writes ``model.json``, ``summary.json`` and ``report.html`` (``report()`` builds the
    :class:`Report`; None: no report) into the folder ``out`` and says so; returns None, or
    ``(where, problem)`` for the command's one-line error (``where`` None when the problem is not
    a file's)."""
    out = Path(out)
    try:
        model.context = context_of(summary, model)      # what lptv validate / simulate read back
        # written together or not at all: a full disk or a second command into the same folder
        # never leaves one fit's model beside another's report
        no_plots = False
        with staged_folder(out, replaces=FIT_FILES) as stage:
            model.save(stage / "model.json")
            write_json(stage / "summary.json", summary)
            if report is not None:
                try:
                    report().write(stage)
                except ImportError:     # the fit is kept whole without its report (as --no-report)
                    no_plots = True
    except OSError as e:
        return e.filename or out, e.strerror or e
    if no_plots:
        return None, PLOTS_EXTRA
    print(f"wrote {out / 'model.json'}, " + (f"{out / 'report.html'}, " if report is not None else "")
          + f"{out / 'summary.json'}")
    return None


def model_figures(rep: Report, fit, whose: str = "the model", *, physical=None, u_unit=None, y_unit=None):
    """The frozen poles and zeros and, for an LPTV model, the coefficients over one period, one panel
    each (with their bands when ``fit`` is a result with a covariance; ``physical`` its scaled
    form from :func:`parameter_section`)."""
    from types import SimpleNamespace

    from lptv import Model, frozen_poles, frozen_zeros, plots

    model = fit if isinstance(fit, Model) else fit.model
    t = np.linspace(0.0, model.period, 400)
    ax = plots.frozen_poles_zeros(t, poles_est=frozen_poles(model, t), zeros_est=frozen_zeros(model, t),
                                  discrete=model.discrete)
    rep.figure(ax.figure, "frozen_poles_zeros.png",
               f"Frozen (instantaneous) poles (x) and zeros (o) of {whose} over one period "
               + ("(z-plane)." if model.discrete else "(s-plane, rad/s)."))
    if model.is_lti:
        return
    src = physical or (SimpleNamespace(model=model, eta_names=model.eta_names, eta=None,
                                       covariance=model.covariance) if isinstance(fit, Model) else fit)
    coefficient_figure(rep, src, u_unit=u_unit, y_unit=y_unit, whose=f"{whose}'s" if whose != "the model" else
                       "the estimated")


def _sig(v, digits=6):
    return "-" if v is None else f"{float(v):.{digits}g}"


def parameter_section(rep: Report, res, *, scale=None, known=None, u_unit=None, y_unit=None,
                      level: float = 0.95):
    """The parameter table with standard deviations and intervals, in the fit's normalisation
    (mean of a_na = 1) or, with ``scale = (name, value)``, in the physical form that sets the mean
    of that coefficient (:mod:`lptv.apps.units`); units from the channels' names where they state
    them. Returns the source of the table (the result or its scaled form)."""
    from lptv import parameter_table
    from lptv.apps.units import coefficient_units, scaled

    model = res.model
    src = scaled(res, *scale) if scale else res
    units = coefficient_units(src.model, u_unit, y_unit, scale)
    rep.heading("Parameters")
    top = f"a{model.na}"
    if scale:
        rep.paragraph(
            f"In physical form: every parameter divided by the mean of {scale[0]} and multiplied by "
            f"{scale[1]:g} (--scale {scale[0]}={scale[1]:g}), so that the mean of {scale[0]} is {scale[1]:g}; "
            f"their standard deviations and {100 * level:g} % intervals carried along by the covariance "
            f"(first order). The fit itself sets the mean of {top} to 1 (the equation holds for any "
            "common factor of its coefficients); its verdict does not depend on the scale. "
            "summary.json keeps both tables.")
    elif known:
        rep.paragraph("The known coefficients (" + ", ".join(f"{k} = {v:g}" for k, v in known.items())
                      + ") fix the scale of the equation: the parameters below are in the units they imply.")
    else:
        example = ("A force driving a mass-spring-damper, m x'' + c x' + k(t) x = F, enters with b0 = 1: "
                   "--scale b0=1 then reads a2 as the mass m, a1 as the damping c and a0 as the stiffness k(t)"
                   if not model.discrete and model.na == 2 and model.nb == 0 else
                   "--scale b0=1, for example, sets the mean of b0 to 1")
        rep.paragraph(
            f"The parameters are normalised: the equation sum_n a_n(t) d^n y/dt^n = sum_m b_m(t) d^m u/dt^m "
            f"holds for any common factor of its coefficients, so the fit sets the mean of {top} to 1 (its "
            "row says 'normalised', without a standard deviation) and every other parameter is relative to it. "
            f"To read them in physical units, name one coefficient whose value you know. {example}, with every "
            "interval scaled alike; --known b0=1 instead fits with b0 fixed at 1 (the same model for a "
            "constant b0, but without the verdict's score tests of one more harmonic).")
    rows = []
    for r in parameter_table(src, level):
        coef = r["name"].split(".")[0]
        unit = r["unit"] or units.get(coef, "")
        fixed = r["kind"] == "normalised"
        note = ("set by --scale" if scale and coef == scale[0] and ".re0" in r["name"] else "normalised") \
            if fixed else ("derived" if r["kind"] == "derived" else "")
        interval = "-" if fixed or r["low"] is None else f"[{_sig(r['low'])}, {_sig(r['high'])}]"
        rows.append([r["name"], _sig(r["value"]), "-" if fixed else _sig(r["std"], 3), interval, unit, note])
    rep.table(["parameter", "value", "std", f"{100 * level:g} % interval", "unit", ""], rows)
    if any(".amp" in r[0] for r in rows):
        rep.paragraph("a0.re1, a0.im1 are the real and imaginary parts of harmonic 1 of a_0(t) = a0.re0 + "
                      "sum_k 2 (a0.rek cos(k w0 t) - a0.imk sin(k w0 t)); a0.amp1 and a0.phase1 the same "
                      "harmonic as amp cos(w0 t + phase).")
    return src


def coefficient_figure(rep: Report, src, *, u_unit=None, y_unit=None, level: float = 0.95, whose="the estimated"):
    """One panel per coefficient over one period with its band (a result or its scaled form)."""
    from lptv import plots
    from lptv.apps.units import coefficient_units, trajectories

    model = src.model
    t = np.linspace(0.0, model.period, 200)
    values, std, names = trajectories(src, t)
    units = coefficient_units(model, u_unit, y_unit, getattr(src, "scale", None))
    fig = plots.coefficient_bands(t, values, std, names=names, units=[units.get(n) for n in names], level=level,
                                  title=f"{whose[0].upper()}{whose[1:]} coefficients over one period")
    scale = getattr(src, "scale", None)
    rep.figure(fig, "coefficients.png",
               f"{whose[0].upper()}{whose[1:]} coefficients a_n(t) and b_m(t) over one period, each on its own "
               f"axis" + (f" with its {100 * level:g} % band from the parameter covariance" if std is not None else "")
               + (f", in the physical form (mean of {scale[0]} = {scale[1]:g})." if scale else
                  f" (normalised: the mean of a{model.na} is 1)."))


def residue_tests_section(rep: Report, res):
    """The verdict's residue tests: a table and the figure, each test under one short name."""
    from lptv import plots

    tests = res.residue_tests
    if tests is None:
        return
    thresholds = plots.residue_test_thresholds(tests)
    rows = []
    for t, thr in zip(tests.tests, thresholds):
        stat = "F" if t.kind == "score" else "z"
        limit = (f"|z| >= {thr[1]:.3g}" if thr[0] is not None else f"{stat} >= {thr[1]:.3g}")
        rows.append([plots.residue_test_label(t), t.name, t.rows.size, f"{stat} = {t.statistic:.3g}", limit,
                     f"{t.p_value:.2g}", f"{t.p_holm:.2g}", "REJECTS" if t.rejects else "no"])
    rep.table(["test", "what it tests", "rows", "statistic", "threshold", "p", "Holm-adjusted p",
               f"rejects at {100 * tests.alpha:g} %"], rows)
    rep.figure(plots.residue_tests(res), "residue_tests.png",
               "The verdict's residue tests, each on its own statistic against its own threshold (dashed): "
               "z, the sum of the rows' normal scores over its standard deviation (standard normal without a "
               "model error; two-sided over all rows with signal, one-sided per group of rows d lines from "
               "the nearest excited line), and F, the score test of one more harmonic on each coefficient "
               "(its degrees of freedom from the rows' noise). A threshold is where the test's p-value "
               "reaches the level Holm's method gives it, 1 % divided by the number of tests not yet "
               "rejected before it (METHOD.md section 7); a red bar rejects.")
