"""A study's finished chunks on disk, so that an interrupted study loses only its running chunks.

:func:`lptv.batch.run_tasks` with ``checkpoint=DIR`` writes each chunk's results as it finishes
to ``DIR/part-<first item>.json`` (append-only; each written to a temporary file and renamed,
so a kill leaves whole parts only) beside ``DIR/study.json``, the study's fingerprint: a hash of
the task function, every item and the shared design. A rerun with the same study reads the
parts and runs only the items they lack; since every item draws its random numbers from its own
seed, the results are the same, bit for bit, as those of an uninterrupted run. A folder that
holds another study (other options, seed or records) is refused, never mixed in.

The parts are JSON, with tags for what JSON lacks (NumPy arrays, tuples, complex numbers,
:class:`Failure`): floats are written by ``repr``, which reads back to the same double.
A chunk that was lost (a worker died, the cluster went away) is not written: it runs again.
"""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any, Dict, List, Optional

import numpy as np

from ..atomic import atomic_open

STUDY = "study.json"
FORMAT = 1


class CheckpointError(ValueError):
    """A checkpoint folder that holds another study, or cannot be used."""


# ------------------------------------------------------------------------------ tagged JSON

def encode(x):
    """Plain JSON values from results: arrays, tuples, complex numbers and Failures tagged."""
    from .executors import Failure

    if isinstance(x, Failure):
        return {"__failure__": [x.message, x.detail]}
    if isinstance(x, np.ndarray):
        if x.dtype.kind not in "biufc":
            raise TypeError(f"cannot store an array of dtype {x.dtype}")
        return {"__array__": encode(x.tolist()), "dtype": x.dtype.str, "shape": list(x.shape)}
    if isinstance(x, np.generic):
        return encode(x.item())
    if isinstance(x, complex):
        return {"__complex__": [x.real, x.imag]}
    if isinstance(x, dict):
        if all(isinstance(k, str) for k in x):
            return {"__dict__": {k: encode(v) for k, v in x.items()}}
        return {"__items__": [[encode(k), encode(v)] for k, v in x.items()]}
    if isinstance(x, tuple):
        return {"__tuple__": [encode(v) for v in x]}
    if isinstance(x, list):
        return [encode(v) for v in x]
    if isinstance(x, np.random.SeedSequence):
        return {"__seed__": [encode(x.entropy), list(x.spawn_key), x.pool_size]}
    if isinstance(x, os.PathLike):
        return {"__path__": os.fspath(x)}
    if x is None or isinstance(x, (bool, int, float, str)):
        return x
    raise TypeError(f"cannot store a {type(x).__name__}")


def decode(x):
    """The inverse of :func:`encode`."""
    from .executors import Failure

    if isinstance(x, list):
        return [decode(v) for v in x]
    if not isinstance(x, dict):
        return x
    if "__dict__" in x:
        return {k: decode(v) for k, v in x["__dict__"].items()}
    if "__tuple__" in x:
        return tuple(decode(v) for v in x["__tuple__"])
    if "__array__" in x:
        return np.array(decode(x["__array__"]), dtype=np.dtype(x["dtype"])).reshape(x["shape"])
    if "__complex__" in x:
        return complex(*x["__complex__"])
    if "__failure__" in x:
        return Failure(*x["__failure__"])
    if "__items__" in x:
        return {decode(k): decode(v) for k, v in x["__items__"]}
    if "__path__" in x:
        return Path(x["__path__"])
    if "__seed__" in x:
        entropy, key, pool = x["__seed__"]
        return np.random.SeedSequence(decode(entropy), spawn_key=tuple(key), pool_size=pool)
    raise ValueError(f"unknown tag in a stored part: {sorted(x)}")


def fingerprint(fn, items, shared) -> str:
    """A hash of the study: the task function, every item and the shared design (by content)."""
    h = hashlib.sha256()
    h.update(f"{fn.__module__}.{fn.__qualname__}\n".encode())
    for x in (shared, *items):
        try:
            h.update(json.dumps(encode(x), sort_keys=True).encode())
        except TypeError:      # an object JSON cannot hold (lptv.Measurements ...): by its pickle
            import pickle

            h.update(pickle.dumps(x, protocol=4))
    return h.hexdigest()


# ------------------------------------------------------------------------------ the folder

class Checkpoint:
    """The parts of one study in a folder (see the module's description)."""

    def __init__(self, directory, fn, items, shared, describe: str = ""):
        self.dir = Path(os.fspath(directory))
        self.n = len(items)
        self.key = fingerprint(fn, items, shared)
        self.describe = describe
        try:
            self.dir.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise CheckpointError(f"checkpoint {self.dir} is not a folder that can be written: "
                                  f"{e.strerror or e}") from None
        study = self.dir / STUDY
        if study.exists():
            try:
                meta = json.loads(study.read_text())
            except (OSError, ValueError) as e:
                raise CheckpointError(f"checkpoint {study} cannot be read: {e}") from None
            if meta.get("fingerprint") != self.key or meta.get("items") != self.n:
                raise CheckpointError(
                    f"checkpoint {self.dir} holds the parts of another study ({meta.get('items')} items, other "
                    "options, seed or records): use another folder, or remove it to start afresh")
        else:
            with atomic_open(study) as f:
                json.dump({"format": FORMAT, "fingerprint": self.key, "items": self.n,
                           "describe": describe}, f, indent=1)

    def load(self) -> Dict[int, Any]:
        """{item index: result} of the parts on disk (a part that cannot be read runs again)."""
        done = {}
        for p in sorted(self.dir.glob("part-*.json")):
            try:
                part = json.loads(p.read_text())
            except (OSError, ValueError):
                continue
            if part.get("fingerprint") != self.key:
                raise CheckpointError(f"checkpoint {p} belongs to another study: remove it")
            for i, r in zip(part["items"], part["results"]):
                done[int(i)] = decode(r)
        return done

    def write(self, indices: List[int], results: List[Any]):
        """One finished chunk, whole or not at all."""
        part = {"fingerprint": self.key, "items": list(indices), "results": [encode(r) for r in results]}
        with atomic_open(self.dir / f"part-{indices[0]:09d}-{len(indices)}.json") as f:
            json.dump(part, f, allow_nan=True)


def stored_items(directory) -> Optional[int]:
    """How many items the parts in ``directory`` hold (None when it holds no study)."""
    d = Path(os.fspath(directory))
    if not (d / STUDY).exists():
        return None
    n = 0
    for p in d.glob("part-*.json"):
        try:
            n += len(json.loads(p.read_text())["items"])
        except (OSError, ValueError, KeyError):
            continue
    return n


def clear(directory):
    """Remove a study's parts and fingerprint from ``directory`` (nothing else in it)."""
    d = Path(os.fspath(directory))
    for p in [*d.glob("part-*.json"), d / STUDY]:
        try:
            p.unlink()
        except FileNotFoundError:
            pass
