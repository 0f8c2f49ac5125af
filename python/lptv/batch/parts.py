"""A study's finished chunks on disk, so that an interrupted study loses only its running chunks.

:func:`lptv.batch.run_tasks` with ``checkpoint=DIR`` writes each chunk's results as it finishes
to ``DIR/part-<first item>-<count>.json`` (append-only; each written to a temporary file and
renamed, so a kill leaves whole parts only) beside ``DIR/study.json``, the study's fingerprint: a
hash of the task function, the shared design and (for a study whose items are its own, such as a
Monte Carlo study's seeds) every item. Each result is stored with its item's own key, a hash of
the item by content (a record given as a file path is hashed with the file's bytes, see
:func:`lptv.batch.records.identify_many`). A rerun reads the parts and runs only the items whose
keys it lacks; where the items are named by labels (the records' files), an unchanged item is
read back, a changed one (a file rewritten since its fit) or a new one runs, and an item no
longer asked for is ignored. Since every item draws its random
numbers from its own seed, the results are the same, bit for bit, as those of an uninterrupted
run. A folder that holds another study (other options or design) is refused, never mixed in.

The parts are JSON, with tags for what JSON lacks (NumPy arrays, tuples, complex numbers,
:class:`Failure`): floats are written by ``repr``, which reads back to the same double.
A chunk that was lost (a worker died, the cluster went away) is not written: it runs again.
"""
from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Dict, List, Optional

import numpy as np

from ..atomic import atomic_open

STUDY = "study.json"
FORMAT = 2


class CheckpointError(ValueError):
    """A checkpoint folder that holds another study, or cannot be used."""


# ------------------------------------------------------------------------------ tagged JSON

def encode(x):
    """Plain JSON values from results: arrays, tuples, complex numbers and Failures tagged."""
    from .common import Failure

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
    from .common import Failure

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


def _hash_into(h, x):
    try:
        h.update(json.dumps(encode(x), sort_keys=True).encode())
    except TypeError:      # an object JSON cannot hold (lptv.Measurements ...): by its pickle
        import pickle

        h.update(pickle.dumps(x, protocol=4))


def fingerprint(fn, shared, keys=None) -> str:
    """A hash of the study: the task function, the shared design (by content) and, when given,
    the items' keys."""
    h = hashlib.sha256()
    h.update(f"{fn.__module__}.{fn.__qualname__}\n".encode())
    _hash_into(h, shared)
    for k in keys or ():
        h.update(k.encode())
    return h.hexdigest()


def item_key(item) -> str:
    """A hash of one item by content (what a stored result is matched by)."""
    h = hashlib.sha256()
    _hash_into(h, item)
    return h.hexdigest()[:32]


@dataclass(frozen=True)
class ResumeStatus:
    """What a checkpoint folder holds for the items asked for, before they run.

    ``reused`` items are read back; ``changed`` items have a stored result under the same label
    (e.g. the same file) but other contents, and run again; ``new`` items run for the first
    time; ``stale`` stored results match no item asked for (kept, not used)."""

    total: int
    reused: int
    changed: int
    new: int
    stale: int


# ------------------------------------------------------------------------------ the folder

class Checkpoint:
    """The parts of one study in a folder (see the module's description).

    ``labels`` (optional, one string per item) name the items across reruns, e.g. the file
    each record comes from: an item whose label is stored with another key has *changed*."""

    def __init__(self, directory, fn, items, shared, describe: str = "", labels=None):
        self.dir = Path(os.fspath(directory))
        self.n = len(items)
        self.keys = [item_key(x) for x in items]
        # without labels the items are the study's (a Monte Carlo study's seeds): they are part
        # of its fingerprint, and other items are another study; with labels (records of files)
        # each result is matched to its item alone, and the items may change between runs
        self.key = fingerprint(fn, shared, None if labels is not None else self.keys)
        self.labels = None if labels is None else [str(x) for x in labels]
        self.describe = describe
        self.status = ResumeStatus(self.n, 0, 0, self.n, 0)
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
            if not isinstance(meta, dict) or meta.get("fingerprint") != self.key or meta.get("format") != FORMAT:
                raise CheckpointError(
                    f"checkpoint {self.dir} holds the parts of another study (other options, seed or design): "
                    "use another folder, or remove it to start afresh")
        else:
            with atomic_open(study) as f:
                json.dump({"format": FORMAT, "fingerprint": self.key, "describe": describe}, f, indent=1)

    def load(self) -> Dict[int, Any]:
        """{item index: result} of the parts on disk whose keys match an item asked for (a part
        that cannot be read runs again); sets :attr:`status`."""
        where: Dict[str, List[int]] = {}
        for i, k in enumerate(self.keys):
            where.setdefault(k, []).append(i)
        done, stored_labels, stale = {}, set(), 0
        for p in sorted(self.dir.glob("part-*.json")):
            try:
                part = json.loads(p.read_text())
                keys, results = part["keys"], part["results"]
            except (OSError, ValueError, KeyError, TypeError):
                continue
            if part.get("fingerprint") != self.key:
                raise CheckpointError(f"checkpoint {p} belongs to another study: remove it")
            for j, (k, r) in enumerate(zip(keys, results)):
                if k in where:
                    value = decode(r)
                    for i in where[k]:
                        done[i] = value
                else:
                    stale += 1
                    labels = part.get("labels")
                    if labels:
                        stored_labels.add(labels[j])
        changed = 0 if self.labels is None else sum(
            1 for i, lab in enumerate(self.labels) if i not in done and lab in stored_labels)
        self.status = ResumeStatus(self.n, len(done), changed, self.n - len(done) - changed, stale)
        return done

    def write(self, indices: List[int], results: List[Any]):
        """One finished chunk, whole or not at all."""
        part = {"fingerprint": self.key, "items": list(indices), "keys": [self.keys[i] for i in indices],
                "results": [encode(r) for r in results]}
        if self.labels is not None:
            part["labels"] = [self.labels[i] for i in indices]
        with atomic_open(self.dir / f"part-{indices[0]:09d}-{len(indices)}-{self.keys[indices[0]][:8]}.json") as f:
            json.dump(part, f, allow_nan=True)


def stored_items(directory) -> Optional[int]:
    """How many results the parts in ``directory`` hold (None when it holds no study); of any
    items, changed or not (:attr:`Checkpoint.status` tells which are of the items asked for)."""
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
