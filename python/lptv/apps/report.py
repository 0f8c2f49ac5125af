"""A small offline HTML report: headings, text, tables and figures (PNG files embedded)."""
from __future__ import annotations

import base64
import html
import io
import json
import os
from pathlib import Path

import numpy as np

from lptv.atomic import atomic_open


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
        fig.savefig(buf, format="png", dpi=110)
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
                 "figcaption{font-size:.92em;color:#444}pre{background:#f6f6f6;padding:.6em;white-space:pre-wrap}")
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


def write_fit(out, model, summary, report):
    """Writes ``model.json``, ``summary.json`` and ``report.html`` (``report()`` builds the
    :class:`Report`) into the folder ``out`` and says so; returns None, or ``(where, problem)``
    for the command's one-line error (``where`` None when the problem is not a file's)."""
    out = Path(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
        model.save(out / "model.json")
        write_json(out / "summary.json", summary)
        report().write(out)
    except OSError as e:
        return e.filename or out, e.strerror or e
    except ImportError:
        return None, PLOTS_EXTRA
    print(f"wrote {out / 'model.json'}, {out / 'report.html'}, {out / 'summary.json'}")
    return None


def model_figures(rep: Report, model, whose: str = "the model"):
    """The frozen poles and zeros and the coefficients of an LPTV ``model`` over one period."""
    from lptv import frozen_poles, frozen_zeros, plots

    t = np.linspace(0.0, model.period, 400)
    ax = plots.frozen_poles_zeros(t, poles_est=frozen_poles(model, t), zeros_est=frozen_zeros(model, t),
                                  discrete=model.discrete)
    rep.figure(ax.figure, "frozen_poles_zeros.png",
               f"Frozen (instantaneous) poles (x) and zeros (o) of {whose} over one period "
               + ("(z-plane)." if model.discrete else "(s-plane, rad/s)."))
    names = [f"a{n}" for n in range(model.na + 1)] + [f"b{m}" for m in range(model.nb + 1)]
    coef = np.hstack([model.a_at(t), model.b_at(t)]).real
    ax = plots.coefficients(t, est=coef, names=names, ylabel="a_n(t), b_m(t)")
    rep.figure(ax.figure, "coefficients.png", "The estimated coefficients a_n(t) and b_m(t) over one period.")
