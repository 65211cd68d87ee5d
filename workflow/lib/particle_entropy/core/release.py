"""A continuous release (issue 53): a source that lets out mass at the rate q per unit time from ``start``
until ``end`` (open: until the observation). The dataclass as core/release.py's exact reference of the
release defines it (another part of issue 53, whose reference, quadrature rules and closed forms join
this module when the two are merged); the runs (models/release_step.py) read its fields and ``mass``."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .sources import SourceError


class ReleaseError(SourceError):
    """A release parameter out of its range: ``param`` the field (rate, start, end) or the observation
    time t, its ``value`` and ``allowed``, the message."""


def _finite(value) -> bool:
    ok = isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)
    return ok and math.isfinite(value)


@dataclass(frozen=True)
class Release:
    """Mass ``rate`` per unit time let out from ``start`` until ``end`` (None: until the observation) [M/T, T].

    A config writes {rate: q, from: t0, until: t1} (``from_spec``)."""

    rate: float
    start: float = 0.0
    end: float | None = None

    def __post_init__(self):
        if not (_finite(self.rate) and self.rate > 0):
            raise ReleaseError("rate", self.rate, f"rate: a number > 0 and finite [M/T], got {self.rate!r}")
        if not _finite(self.start):
            raise ReleaseError("start", self.start, f"start: a finite time [T], got {self.start!r}")
        if self.end is not None and not (_finite(self.end) and self.end > self.start):
            raise ReleaseError(
                "end", self.end, f"end: a finite time > start = {self.start!r} [T], or None (open), got {self.end!r}"
            )

    @staticmethod
    def from_spec(spec: Mapping) -> Release:
        """The release a config writes: {rate: q, from: t0 (default 0), until: t1 (default open)}."""
        extra = sorted(set(spec) - {"rate", "from", "until"})
        if extra:
            raise ReleaseError(extra[0], spec[extra[0]], f"{extra[0]}: not a key of a release (rate, from, until)")
        return Release(spec.get("rate"), spec.get("from", 0.0), spec.get("until"))

    def check(self, t: float) -> None:
        """ReleaseError unless the observation time t is finite and after ``start``."""
        if not (_finite(t) and t > self.start):
            raise ReleaseError("t", t, f"t: a finite time > the release's start {self.start!r} [T], got {t!r}")

    def ages(self, t: float) -> tuple[float, float]:
        """(s_lo, s_hi): the youngest and oldest age t - tau of the mass released by t [T]."""
        self.check(t)
        return (0.0 if self.end is None else max(t - self.end, 0.0)), t - self.start

    def mass(self, t: float) -> float:
        """M(t) = q (min(end, t) - start)^+ [M] (0 before the start)."""
        stop = t if self.end is None else min(self.end, t)
        return self.rate * max(stop - self.start, 0.0)
