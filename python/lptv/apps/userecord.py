"""What ``lptv validate`` and ``lptv simulate`` share: the saved model and the record read as it asks.

The model (model.json of ``lptv identify``) says its channels, period and sampling; the record's
options (those of ``lptv identify``) default to them, and a record that contradicts them (another
period, sampling or channel, a unit that differs) is a one-line error with exit status 2.
"""
from __future__ import annotations

import json
import os
import re
import sys

import numpy as np

from lptv import MimoModel, Model, read_measurements
from lptv.apps.options import in_option_terms, positive
from lptv.records.channels import split_unit
from lptv.records.measurements import FileError, read_input
from lptv.use.predict import whole_periods


def add_model_and_record(p, *, output: bool):
    """MODEL and FILE, and the reading options of lptv identify (their defaults: the model's)."""
    p.add_argument("model", metavar="MODEL.json", help="a model written by lptv identify (model.json)")
    p.add_argument("file", metavar="FILE", help="the record: .csv, .npz or .mat, as for lptv identify")
    p.add_argument("--input", metavar="NAME", help="the input channel(s), a comma list for several (default: the "
                   "model's, as model.json names them)")
    if output:
        p.add_argument("--output", metavar="NAME", help="the output channel(s) (default: the model's)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--w0", type=float, help="fundamental of the period (rad/s); must be the model's")
    g.add_argument("--period", type=float, metavar="T0", help="the period in seconds; must be the model's")
    s = p.add_mutually_exclusive_group()
    s.add_argument("--fs", type=float, metavar="HZ", help="sampling frequency of the record (default: the file's "
                   "time or stored fs, else the model's)")
    s.add_argument("--dt", type=float, metavar="S", help="sampling time of the record (s), 1 / fs")
    p.add_argument("--time", metavar="NAME", help="a time column or variable (default: one named t or time)")
    p.add_argument("--periods", type=int, metavar="P", help="number of periods in a CSV record (or a vector)")
    p.add_argument("--trim", action="store_true", help="drop the first samples of a long record to keep whole periods")
    p.add_argument("--skip-periods", type=int, default=0, metavar="K", help="drop the first K periods")
    p.add_argument("--detrend", action="store_true", help="take a linear drift out of each channel")
    p.add_argument("--out", help="output folder (default: <file stem>-validate/ or pred.csv)")


def fail(command, where, problem, status=2) -> int:
    text = " ".join(str(problem).split()) or type(problem).__name__
    print(f"lptv {command}: error: {where}: {in_option_terms(text, {'fs': '--fs', 'lines': '--lines'})}",
          file=sys.stderr)
    return status


def _same_channel(a: str, b: str) -> bool:
    """One channel: the same name up to case, and the same unit where both state one."""
    (na, ua), (nb, ub) = split_unit(a), split_unit(b)
    return na == nb and (ua is None or ub is None or ua == ub)


def load_model(path):
    """An lptv.Model or lptv.MimoModel from its JSON file (by its format)."""
    if os.path.exists(path) and not os.path.isfile(path):
        # a FIFO with no writer would keep the open below waiting for ever
        raise FileError("is not a regular file (a FIFO, a device or a folder): give the model's JSON file")
    try:
        with open(path, "rb") as f:
            head = json.loads(f.read().decode("utf-8", errors="replace"))
    except (OSError, ValueError):
        head = None
    if isinstance(head, dict) and head.get("format") == "lptv.MimoModel":
        return MimoModel.load(path)
    return Model.load(path)


def _names(model, given, key, default):
    ctx = model.context
    names = [n.strip() for n in given.split(",")] if given else (list(ctx[key]) if ctx else None)
    count = getattr(model, "n_inputs" if key == "inputs" else "n_outputs", 1)
    if names is None:
        names = [default] if count == 1 else [f"{default}{i + 1}" for i in range(count)]
    if len(names) != count:
        raise FileError(f"--{key[:-1]}: {len(names)} channel(s) named, but the model has {count}")
    if given and ctx:
        for n, m in zip(names, ctx[key]):
            if not _same_channel(n, m):
                raise FileError(f"--{key[:-1]} {n}: the model's {key[:-1]} is '{m}' (a record of other channels "
                                "is not this model's)")
    return names if count > 1 else names[0]


def _period(args, model):
    period = positive(args.period, "--period")
    if period is None and positive(args.w0, "--w0") is not None:
        period = 2 * np.pi / args.w0
    if period is not None and not np.isclose(period, model.period, rtol=1e-9, atol=0):
        raise FileError(f"--period {period:g} s (--w0 {2 * np.pi / period:g} rad/s), but the model's period is "
                        f"{model.period:g} s (w0 = {model.w0:g} rad/s)")
    return model.period


def check_channels(model, meas, output=True):
    """The file's channels against the model's: the same names up to case, and the same units."""
    ctx = model.context
    if not ctx:
        return
    got = [("inputs", meas.input)] + ([("outputs", meas.output)] if output else [])
    for key, names in got:
        names = list(names) if isinstance(names, (list, tuple)) else [names]
        for n, m in zip(names, ctx[key]):
            if not _same_channel(n, m):
                raise FileError(f"the file's {key[:-1]} '{n}' is not the model's '{m}' (another channel, or "
                                "another unit)")


def check_sampling(model, fs, what="the record"):
    """fs (Hz) against the model's: a discrete model's 1 / ts, a continuous one's record's fs."""
    ctx = model.context
    if model.discrete and not np.isclose(fs * model.ts, 1.0, rtol=1e-9, atol=0):
        raise FileError(f"{what} is sampled at {fs:g} Hz, but the discrete-time model at 1 / ts = "
                        f"{1 / model.ts:g} Hz")
    if not model.discrete and ctx and ctx["fs"] is not None and not np.isclose(fs, ctx["fs"], rtol=1e-9, atol=0):
        raise FileError(f"{what} is sampled at {fs:g} Hz, but the model was identified from a record sampled at "
                        f"{ctx['fs']:g} Hz (its anti-alias filter and hold are part of what it identified: "
                        "record at the same fs)")


def read(args, model, *, output=True, periodic=True):
    """The record as the options say, the model's defaults filled in and checked against it."""
    u_name = _names(model, args.input, "inputs", "u")
    y_name = _names(model, getattr(args, "output", None), "outputs", "y") if output else u_name
    period = _period(args, model)
    fs = positive(args.fs, "--fs")
    if fs is None and positive(args.dt, "--dt") is not None:
        fs = 1.0 / args.dt
    fallback = (1.0 / model.ts) if model.discrete else (model.context or {}).get("fs")
    kw = dict(u=u_name, y=y_name, time=args.time, detrend=args.detrend, period=period)
    # periods as lptv identify cuts them; a record that does not repeat (--one-record, simulate) as
    # lptv identify --one-record reads it: whole periods of the model, its first samples dropped to keep them
    kw.update(periods=args.periods, trim=args.trim, skip_periods=args.skip_periods) if periodic else \
        kw.update(trim=True)
    reader = read_measurements if output else read_input    # simulate: a record of the input alone
    if not output:
        del kw["y"]
    try:
        meas = reader(args.file, fs=fs, **kw)
    except FileError:
        if fs is not None or fallback is None:
            raise
        meas = reader(args.file, fs=fallback, **kw)    # no time of its own: sampled as the model's
    fs, source = (meas.fs, meas.fs_source) if meas.fs is not None else (fallback, "the model")
    if fs is None:
        raise FileError("the sampling frequency is unknown: give --fs (the file has no time column or stored fs, "
                        "and the model none)")
    check_channels(model, meas, output)
    check_sampling(model, fs)
    if periodic:
        whole_periods(model, meas.u.shape[1], fs, "the record's periods")
    return meas, fs, source


def time_column(args, meas, fs):
    """(name, values) of the file's time, or ('time [s]', k / fs) when the file has none."""
    n = meas.u.shape[0] * meas.u.shape[1]
    src = meas.fs_source or ""
    hit = re.match(r"(?:column|variable) '(.+)'$", src)
    if hit:
        t = np.asarray(read_input(args.file, fs=fs, period=meas.w0 and 2 * np.pi / meas.w0, trim=True,
                                  u=hit.group(1)).u).reshape(-1)
        return hit.group(1), t[t.size - n:]
    return "time [s]", np.arange(n) / fs
