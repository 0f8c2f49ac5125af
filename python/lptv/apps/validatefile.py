"""``lptv validate MODEL.json FILE``: a saved model, fixed, against a fresh record (lptv.validate).

The record is read with the options of ``lptv identify`` (their defaults: the model's channels,
period and sampling; a record that contradicts them is an error). The model is not refitted:
its residues on the record are judged against the record's own noise by the verdict's tests
with the model fixed, a score test per coefficient says which parameters the record would
change, and the simulation fit in percent compares the measured output with the predicted
one. Writes summary.json and report.html (measured against predicted) into ``--out``.
Exit status: 0 when the model is consistent with the record, 3 for MODEL ERRORS (as ``lptv
identify``), 2 for a file or options that cannot be used, 1 for a computation that failed.

Example::

    lptv validate rig-lptv/model.json run2.csv --out run2-validate
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from lptv import NumericalError, validate
from lptv.apps.options import MODEL_REJECTED, count, dropped_note, output_folder, parse_lines
from lptv.apps.report import Report, write_json
from lptv.apps.userecord import add_model_and_record, fail, load_model, read, time_column
from lptv.records.measurements import FileError


def add_parser(sub):
    p = sub.add_parser("validate", help="a saved model against a fresh record (no refit): verdict and fit in %%",
                       description=__doc__.split("\n\n")[1], formatter_class=argparse.RawDescriptionHelpFormatter,
                       epilog="examples:\n"
                              "  lptv validate rig-lptv/model.json run2.csv\n"
                              "  lptv validate rig-lptv/model.json run2.csv --skip-periods 2 --out run2-validate\n"
                              "  lptv validate run-lptv/model.json startup.csv --one-record")
    add_model_and_record(p, output=True)
    p.add_argument("--lines", help="the rows of the residues, e.g. 1-243 (default: every usable line)")
    p.add_argument("--one-record", action="store_true",
                   help="the file is one record that does not repeat, from rest at its first sample: the residual "
                        "of the prediction from rest is tested (lptv identify --one-record's verdict)")
    p.add_argument("--no-report", action="store_true", help="write summary.json only (no report.html)")
    return p


def run(args) -> int:
    try:
        output_folder(args.out)
    except OSError as e:
        return fail("validate", e.filename or args.out, e.strerror or e)
    try:
        model = load_model(args.model)
    except (OSError, ValueError) as e:
        return fail("validate", args.model, getattr(e, "strerror", None) or e)
    try:
        lines = None if args.lines is None else parse_lines(args.lines)
        if isinstance(lines, str):
            raise FileError("--lines: give line numbers or ranges (the rows of the residues)")
        meas, fs, source = read(args, model, periodic=not args.one_record)
        if args.one_record:
            res = validate(model, meas.u.reshape(-1), meas.y.reshape(-1), fs=fs, lines=lines, one_record=True)
        else:
            res = validate(model, meas.u, meas.y, fs=fs, lines=lines)
        t_name, t = time_column(args, meas, fs)
    except NumericalError as e:
        return fail("validate", args.file, e, status=1)
    except (FileError, ValueError) as e:
        return fail("validate", args.file, e)
    out = Path(args.out) if args.out else Path(Path(args.file).stem + "-validate")
    shape = "one record" if args.one_record else f"{count(meas.u.shape[0], 'period')} of {meas.u.shape[1]} samples"
    fits = np.atleast_1d(res.fit_percent)
    outputs = list(model.context["outputs"]) if model.context else [f"y{i + 1}" for i in range(fits.size)]
    print(f"lptv validate: {args.model} against {args.file} ({shape}, fs = {fs:g} Hz from {source or '--fs'}; "
          f"the model fixed) -> {out}/")
    if dropped_note(meas):
        print(f"  {dropped_note(meas)}")
    print(f"  verdict: {res.verdict}")
    for name, f in zip(outputs, fits):
        print(f"  simulation fit of {name}: {f:.2f} %")
    for c in res.coefficient_tests:
        mark = "CHANGED" if c.rejects else "kept"
        print(f"  {c.name:<4} {mark:<8} chi2 = {c.statistic:8.3g} on {len(c.parameters)} dof, p = {c.p_value:.2g}")
    for note in res.notes:
        print(f"  note: {note}")
    summary = _summary(args, model, res, fs, outputs)
    try:
        out.mkdir(parents=True, exist_ok=True)
        write_json(out / "summary.json", summary)
        if not args.no_report:
            _report(args, res, t, t_name, outputs, summary).write(out)
    except OSError as e:
        return fail("validate", e.filename or out, e.strerror or e)
    except ImportError:
        print("  (no report.html: it needs matplotlib, pip install 'lptv[plots]')")
    print(f"wrote {out / 'summary.json'}" + ("" if args.no_report else f", {out / 'report.html'}"))
    return 0 if res.model_ok else MODEL_REJECTED


def _summary(args, model, res, fs, outputs) -> dict:
    return {
        "model": str(args.model), "file": str(args.file), "route": res.route, "fs": fs,
        "verdict": res.verdict, "model_ok": bool(res.model_ok), "model_errors": list(res.model_errors),
        "fit_percent": {n: float(f) for n, f in zip(outputs, np.atleast_1d(res.fit_percent))},
        "noise": res.noise, "n_lines": int(res.lines.size),
        "coefficient_tests": [{"coefficient": c.name, "parameters": list(c.parameters),
                               "change": [float(x) for x in c.change], "std": [float(x) for x in c.std],
                               "statistic": c.statistic, "p_value": c.p_value, "p_holm": c.p_holm,
                               "changed": bool(c.rejects)} for c in res.coefficient_tests],
        "notes": list(res.notes),
    }


def _report(args, res, t, t_name, outputs, summary) -> Report:
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    rep = Report(f"lptv validate: {Path(args.file).name}")
    rep.paragraph(f"The model {args.model}, fixed (no refit), against the record {args.file} "
                  f"({res.route}): its residues judged against the record's own noise, and its predicted "
                  "output against the measured one.")
    rep.verdict(res.verdict, res.model_ok)
    y, yh = np.atleast_2d(res.y.T).T, np.atleast_2d(res.y_hat.T).T
    for j, name in enumerate(outputs):
        fig = Figure(figsize=(7.5, 3.6))
        ax = fig.add_subplot()
        ax.plot(t, y[:, j], lw=0.8, label=f"measured {name}")
        ax.plot(t, yh[:, j], lw=0.8, ls="--", label="predicted")
        ax.plot(t, y[:, j] - yh[:, j], lw=0.6, label="measured - predicted")
        ax.set_xlabel(t_name)
        ax.set_ylabel(name)
        ax.legend(fontsize=8, loc="upper right")
        fig.tight_layout()
        how = "from rest at the first sample" if res.route == "one record" else \
            "in periodic steady state from the measured input"
        rep.figure(fig, f"measured_predicted_{j}.png",
                   f"Measured {name} and the model's prediction {how}: fit "
                   f"{np.atleast_1d(res.fit_percent)[j]:.2f} % = 100 (1 - ||y - yhat|| / ||y - mean y||).")
    if res.coefficient_tests:
        rep.heading("What the record would change")
        rep.paragraph("Per coefficient, the Gauss-Newton step from the fixed model that the record asks for, "
                      "against its spread when the model is right (the record's noise and the model's own "
                      "covariance): a chi-square score test; Holm-adjusted with the residue tests.")
        rep.table(["coefficient", "parameters", "change", "std", "chi2", "p", "Holm p"],
                  [[c.name, ", ".join(c.parameters), ", ".join(f"{x:+.3g}" for x in c.change),
                    ", ".join(f"{x:.2g}" for x in c.std), f"{c.statistic:.3g}", f"{c.p_value:.2g}",
                    f"{c.p_holm:.2g}"] for c in res.coefficient_tests])
    if res.route == "periods" and res.tests:
        rep.heading("The residue tests")
        rep.table(["test", "rows", "statistic", "p", "Holm p"],
                  [[x.name, x.rows.size, f"{x.statistic:.3g}", f"{x.p_value:.2g}", f"{x.p_holm:.2g}"]
                   for x in res.tests])
    for note in res.notes:
        rep.paragraph(f"Note: {note}.")
    return rep
