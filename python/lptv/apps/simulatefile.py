"""``lptv simulate MODEL.json FILE --input NAME``: the model's output for a file's input.

From rest at the first sample by default (the transient included), or with ``--steady-state``
the periodic steady state of the record repeated (whole periods of the model):
:func:`lptv.predict`. Writes a CSV with the file's time column and the prediction, one column
per output named after the model's output channel and unit (``--out``, default
``<file stem>-pred.csv``). Exit status 0; 2 for a file or options that cannot be used; 1 for a
computation that failed.

Example::

    lptv simulate rig-lptv/model.json run2.csv --input force --out pred.csv
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from lptv import NumericalError, predict
from lptv.apps.userecord import add_model_and_record, fail, load_model, read, time_column
from lptv.atomic import atomic_open
from lptv.records.measurements import FileError


def add_parser(sub):
    p = sub.add_parser("simulate", help="the output a saved model predicts for a file's input",
                       description=__doc__.split("\n\n")[1], formatter_class=argparse.RawDescriptionHelpFormatter,
                       epilog="examples:\n"
                              "  lptv simulate rig-lptv/model.json run2.csv --input force --out pred.csv\n"
                              "  lptv simulate rig-lptv/model.json run2.csv --steady-state")
    add_model_and_record(p, output=False)
    p.add_argument("--steady-state", action="store_true",
                   help="the periodic steady state of the record repeated (whole periods of the model) instead "
                        "of the response from rest at the first sample")
    return p


def run(args) -> int:
    try:
        model = load_model(args.model)
    except (OSError, ValueError) as e:
        return fail("simulate", args.model, getattr(e, "strerror", None) or e)
    try:
        meas, fs, source = read(args, model, output=False, periodic=False)
        n = meas.u.shape[0] * meas.u.shape[1]
        u = meas.u.reshape(n, -1)
        y = predict(model, u, fs=fs, initial="steady" if args.steady_state else "rest")
        t_name, t = time_column(args, meas, fs)
    except NumericalError as e:
        return fail("simulate", args.file, e, status=1)
    except (FileError, ValueError) as e:
        return fail("simulate", args.file, e)
    outputs = list(model.context["outputs"]) if model.context else \
        (["y"] if y.ndim == 1 else [f"y{i + 1}" for i in range(y.shape[1])])
    out = Path(args.out) if args.out else Path(Path(args.file).stem + "-pred.csv")
    table = np.column_stack([t, y])
    try:
        with atomic_open(out) as f:
            f.write(",".join([t_name] + outputs) + "\n")
            np.savetxt(f, table, fmt="%.17g", delimiter=",")
    except OSError as e:
        return fail("simulate", e.filename or out, e.strerror or e)
    how = "periodic steady state" if args.steady_state else "from rest at the first sample"
    print(f"lptv simulate: {args.file} ({n} samples, fs = {fs:g} Hz from {source or '--fs'}) -> {out}: "
          f"{', '.join(outputs)} predicted by {args.model}, {how}")
    if meas.trimmed:
        print(f"dropped at the start: {meas.trimmed} samples (the record is read in whole periods of the model)")
    return 0
