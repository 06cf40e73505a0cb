"""The bytes of a checkpoint (:mod:`oceangnc.core.checkpoint`): packing, and reading them back checked
whole before anything is restored.

A ``checkpoint.npz`` is a NumPy ``.npz`` archive of plain arrays: ``checkpoint.json`` (the UTF-8 JSON
document as ``uint8``), the state arrays ``a0``, ``a1``, ... and ``checkpoint.sha256``, the SHA-256
(hex, as ``uint8``) of the JSON document's bytes followed by every state array (name, dtype, shape and
bytes, in name order). So the JSON part (the log position, the clock, the state tree) is covered by
the same checksum as the arrays: a changed byte anywhere is refused before anything is read from it.

:func:`read` checks, in this order, each failure one line (:class:`~oceangnc.errors.InputError`):
the archive (a zip whose members together expand to at most the checkpoint size limit; no member is
unpickled), the checksum, the document (a JSON object nested at most :data:`MAX_DEPTH` levels, the
format and version) and the clock's fields (types and ranges). Arrays are then matched one by one
against the live simulation by the decoder (shape and dtype, :mod:`oceangnc.core.checkpoint`).
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import zipfile
from typing import Any

import numpy as np

from ..errors import InputError
from .files import LIMIT_CHECKPOINT

VERSION = 3
FORMAT = "oceangnc-checkpoint"
DOC = "checkpoint.json"  #: the JSON member of the archive
SUM = "checkpoint.sha256"  #: the checksum member
MAX_DEPTH = 100  #: levels of JSON nesting a document may have (capture refuses states deeper than 64)


def checksum(doc_bytes: bytes, arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 (hex) of the JSON document's bytes and every array (name, dtype, shape, bytes)."""
    h = hashlib.sha256()
    h.update(len(doc_bytes).to_bytes(8, "little"))
    h.update(doc_bytes)
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(f"{name}\0{a.dtype.str}\0{a.shape}\0".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def pack(doc: dict, arrays: dict[str, np.ndarray]) -> bytes:
    """The bytes of a ``checkpoint.npz`` holding ``doc`` (JSON data) and ``arrays`` with their checksum."""
    text = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    digest = checksum(text, arrays).encode("ascii")
    members: dict[str, Any] = {
        DOC: np.frombuffer(text, dtype=np.uint8),
        SUM: np.frombuffer(digest, dtype=np.uint8),
        **arrays,
    }
    buf = io.BytesIO()
    np.savez(buf, **members)
    return buf.getvalue()


def _depth_ok(node, limit: int) -> bool:
    """True when the JSON value ``node`` is nested at most ``limit`` levels (iterative: no recursion)."""
    stack = [(node, 1)]
    while stack:
        v, d = stack.pop()
        if isinstance(v, (dict, list)):
            if d > limit:
                return False
            stack.extend((x, d + 1) for x in (v.values() if isinstance(v, dict) else v))
    return True


def _members(blob: bytes, name: str) -> dict[str, np.ndarray]:
    with zipfile.ZipFile(io.BytesIO(blob)) as zf:
        infos = zf.infolist()
        if len(infos) > 100_000 or sum(i.file_size for i in infos) > LIMIT_CHECKPOINT:
            raise InputError(f"{name} is refused: its members expand to more than the checkpoint size limit")
    with np.load(io.BytesIO(blob), allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


def read(blob: bytes, name: str = "checkpoint") -> tuple[dict, dict[str, np.ndarray]]:
    """The JSON document and state arrays of a checkpoint's bytes, checked whole (module docstring);
    a one-line InputError otherwise. Nothing is unpickled."""
    if not blob.startswith(b"PK\x03\x04"):
        raise InputError(f"{name} is not an oceangnc checkpoint (not a .npz archive)")
    try:
        members = _members(blob, name)
        raw = members.pop(DOC)
        digest = members.pop(SUM, None)
        for m in (raw, digest):
            if not (isinstance(m, np.ndarray) and m.dtype == np.uint8 and m.ndim == 1):
                raise ValueError("its document or checksum member is missing or not bytes")
        text = raw.tobytes()
    except InputError:
        raise
    except (ValueError, KeyError, OSError, EOFError, MemoryError, zipfile.BadZipFile, NotImplementedError) as e:
        msg = str(e).splitlines()[0] if str(e) else ""
        raise InputError(f"{name} is unreadable: {type(e).__name__}: {msg}") from None
    if digest is None or digest.tobytes() != checksum(text, members).encode("ascii"):
        raise InputError(f"{name} is damaged: its document and arrays do not match their SHA-256 checksum")
    try:
        doc = json.loads(text.decode("utf-8"))
    except RecursionError:
        raise InputError(f"{name} is refused: its JSON document is nested too deeply") from None
    except (ValueError, UnicodeDecodeError) as e:
        raise InputError(f"{name} is unreadable: {type(e).__name__}: {str(e).splitlines()[0]}") from None
    if not _depth_ok(doc, MAX_DEPTH):
        raise InputError(f"{name} is refused: its JSON document is nested more than {MAX_DEPTH} levels deep")
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise InputError(f"{name} has an unknown format")
    if doc.get("version") != VERSION:
        raise InputError(f"{name} has format version {doc.get('version')!r}; this oceangnc reads version {VERSION}")
    check_clock(doc, name)
    return doc, members


def _is_int(v, lo: int = 0) -> bool:
    return type(v) is int and lo <= v < 2**62


def check_run(doc: dict, name: str) -> None:
    """The fields a run's checkpoint adds (:class:`~oceangnc.core.checkpoint.Checkpointer`): the log
    position and time, of their types and ranges, else a one-line InputError."""
    log = doc.get("log")
    if not (isinstance(log, dict) and _is_int(log.get("rows")) and _is_int(log.get("parts"))):
        raise InputError(f"{name} is refused: its log position must be two integers >= 0")
    if not (type(doc.get("t")) in (int, float) and math.isfinite(doc["t"]) and doc["t"] >= 0):
        raise InputError(f"{name} is refused: its time must be a finite number >= 0")


def check_clock(doc: dict, name: str) -> None:
    """The document's clock fields: of their types and ranges, else a one-line InputError."""
    st = doc.get("sim")
    bad = None
    if not isinstance(st, dict):
        bad = "it has no clock"
    elif not (_is_int(st.get("k")) and _is_int(st.get("done_k"), -1)):
        bad = "its step counts must be integers >= 0"
    elif not (isinstance(st.get("t"), (int, float)) and math.isfinite(st["t"]) and st["t"] >= 0):
        bad = "its clock time must be a finite number >= 0"
    elif not (isinstance(st.get("fire_count"), list) and all(_is_int(n) for n in st["fire_count"])):
        bad = "its block fire counts must be integers >= 0"
    elif st.get("log_signals") is not None and not (
        isinstance(st["log_signals"], list) and all(isinstance(s, str) for s in st["log_signals"])
    ):
        bad = "its logged signals must be a list of names"
    elif not all(isinstance(st.get(k), list) for k in ("plant_names", "block_names", "plants", "blocks", "rng")):
        bad = "its plants, blocks and generators must be lists"
    elif not (
        len(st["plants"]) == len(st["plant_names"])
        and len(st["blocks"]) == len(st["block_names"]) == len(st["rng"]) == len(st["fire_count"])
    ):
        bad = "it must hold one state per plant and per block"
    elif not all(isinstance(p, dict) for p in st["plants"]) or not all(isinstance(r, dict) for r in st["rng"]):
        bad = "its plant and generator states must be JSON objects"
    elif not all(
        isinstance(b, list) and len(b) == 2 and (b[0] == "custom" or (b[0] == "dict" and isinstance(b[1], dict)))
        for b in st["blocks"]
    ):
        bad = "its block states must be [kind, state] pairs"
    elif doc.get("every") is not None and not (
        isinstance(doc["every"], (int, float)) and math.isfinite(doc["every"]) and doc["every"] > 0
    ):
        bad = "its checkpoint period must be a number > 0"
    if bad is not None:
        raise InputError(f"{name} is refused: {bad}")
