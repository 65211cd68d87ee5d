"""A reactive scene's reference file (scenes/reference.py writes it): its key, its checksum and
its checked reading, which a simulation job needs to judge its runs (so that the job imports no
experiment). The file carries the SHA-256 of its own canonical content (``sha256``); ``read`` uses it
only when that holds and its digest is both its file's name and its physics' (``problem``)."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import numpy as np

from .io import TableReadError, digest


def key(physics: dict) -> str:
    """A reference's key: a digest of its physics (core/io.digest)."""
    return digest(physics)


def content_sha256(ref: dict) -> str:
    """SHA-256 of a reference's canonical JSON (sorted keys, no spaces), its ``sha256`` left out."""
    text = json.dumps({k: v for k, v in ref.items() if k != "sha256"}, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


class ReferenceFileError(TableReadError):
    """A reference file that cannot be used; the one-line message names it (core.io's
    exit_on_table_errors prints it without a traceback)."""


def _load(path: str | os.PathLike) -> tuple[dict | None, str | None]:
    """The reference at ``path`` as JSON and None, or None and why it cannot be used: not a
    regular file, unreadable, not UTF-8 JSON of an object, no checksum or one its content does
    not match, or a digest other than its file's name or its physics'."""
    path = Path(path)
    if not path.is_file():  # never read a pipe (it would block) or a folder
        what = "a folder" if path.is_dir() else "a link to nothing" if path.is_symlink() else "not a regular file"
        return None, f"it is {what}"
    try:
        ref = json.loads(path.read_bytes().decode("utf-8"))
    except OSError as e:
        return None, f"it cannot be read ({e.strerror or type(e).__name__})"
    except (UnicodeDecodeError, ValueError, RecursionError):
        return None, "it is not UTF-8 JSON"
    if not isinstance(ref, dict):
        return None, "it is not a JSON object"
    if not isinstance(ref.get("sha256"), str):
        return None, "it carries no checksum"
    got = content_sha256(ref)
    if got != ref["sha256"]:
        return None, f"its content's SHA-256 {got[:12]}... differs from its recorded {ref['sha256'][:12]}"
    if ref.get("digest") != path.stem:
        return None, f"its digest {str(ref.get('digest'))[:20]!r} is not its name's: another reference"
    try:
        physics_digest = key(ref["physics"])
    except (KeyError, TypeError, ValueError):
        return None, "it names no physics"
    if physics_digest != path.stem:
        return None, f"its physics' digest {physics_digest} is not its name's"
    return ref, None


def problem(path: str | os.PathLike) -> str | None:
    """Why the reference file at ``path`` cannot be used (``_load``), or None."""
    return _load(path)[1]


def read(path: str | os.PathLike) -> dict:
    """A reference written by ``write``, its points and values as arrays; ReferenceFileError (one
    line naming the file) when ``problem`` finds one."""
    ref, why = _load(path)
    if why:
        raise ReferenceFileError(f"corrupt reference {path}: {why}; the next run sets it aside and rebuilds it")
    try:
        for name in ("points", "a_points", "a_error", "c_points", "c_error", "times", "product_series"):
            ref[name] = np.asarray(ref[name], dtype=np.float64)
    except (KeyError, TypeError, ValueError):  # whole, but of another layout
        raise ReferenceFileError(f"reference {path}: its {name} is no list of numbers; delete it and rerun") from None
    for name in ("a_asymptotic", "c_asymptotic"):  # references written before the flag hold none
        if name in ref:
            ref[name] = np.asarray(ref[name], dtype=bool)
    return ref
