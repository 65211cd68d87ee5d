"""One simulation's settings, their defaults (the paper's, experiments.md) and their checks."""

from __future__ import annotations

import math
import zlib
from dataclasses import asdict, dataclass

import numpy as np

from .gauss import FGT_TOLERANCE, FGT_TOLERANCE_RANGE

METHODS = ("pt", "mtpt", "fd")
KERNELS = {"pt": ("bins", "fixed", "adaptive"), "mtpt": ("collision", "sph"), "fd": ("implicit", "explicit")}
DEFAULT_KERNEL = {"pt": "bins", "mtpt": "collision", "fd": "implicit"}
TRANSFER_METHODS = ("auto", "direct", "fgt", "taylor")
SCHEMES = ("symmetric", "sequential")

PAPER = {
    "D": 1e-3,  # diffusion coefficient [L^2/T]
    "t_final": 1000.0,  # [T]
    "dt0": 0.01,  # first step [T]
    "dt_growth": 1.05,  # dt_{n+1} = growth * dt_n
    "omega": 10.0,  # particle domain length, positions on [-omega/2, omega/2] [L]
    "fd_length": 12.0,  # FD domain [-6, 6] [L]
    "fd_dt": 0.05,  # FD fixed step [T]
    "fixed_kernel_time": 1.0,  # fixed PT kernel has variance 2 D x this time [T]
}


class SettingError(ValueError):
    """A setting outside its allowed range; the message names setting, value and range."""

    def __init__(self, name: str, value, allowed: str):
        super().__init__(f"{name}={value!r} is not allowed: {allowed}")
        self.name = name


@dataclass(frozen=True)
class RunConfig:
    method: str = "mtpt"
    kernel: str | None = None
    n: int = 300
    eta: float = 1.0
    D: float = PAPER["D"]
    t_final: float = PAPER["t_final"]
    dt0: float | None = None  # None: the paper's (0.01 for particles, 0.05 for FD)
    dt_growth: float | None = None  # None: 1.05 for particles, 1 (fixed) for FD
    truncation: float | None = None  # None: whole Gaussian; else kernel widths
    seed: int = 0
    omega: float = PAPER["omega"]
    fd_length: float = PAPER["fd_length"]
    fixed_kernel_time: float = PAPER["fixed_kernel_time"]
    transfer_method: str = "auto"
    transfer_tolerance: float = FGT_TOLERANCE  # FGT error <= this x sum of |weights| in reach
    scheme: str = "symmetric"  # symmetric (Eqs. 16-21) or sequential (the authors' loop)

    def resolved(self) -> "RunConfig":
        """Fill method-dependent defaults and check every setting."""
        kernel = self.kernel if self.kernel is not None else DEFAULT_KERNEL.get(self.method)
        fd = self.method == "fd"
        dt0 = self.dt0 if self.dt0 is not None else (PAPER["fd_dt"] if fd else PAPER["dt0"])
        growth = self.dt_growth if self.dt_growth is not None else (1.0 if fd else PAPER["dt_growth"])
        cfg = RunConfig(**{**asdict(self), "kernel": kernel, "dt0": dt0, "dt_growth": growth})
        cfg.check()
        return cfg

    def check(self) -> None:
        if self.method not in METHODS:
            raise SettingError("method", self.method, f"one of {', '.join(METHODS)}")
        if self.kernel not in KERNELS[self.method]:
            raise SettingError("kernel", self.kernel, f"for method {self.method}: one of {', '.join(KERNELS[self.method])}")
        if not isinstance(self.n, (int, np.integer)) or self.n < 1:
            raise SettingError("n", self.n, "an integer >= 1")
        if self.method == "fd" and (self.n < 2 or self.n % 2):
            raise SettingError("n", self.n, "for fd an even number of intervals >= 2, so that a node sits at x = 0")
        check_range("eta", self.eta, 0.0, 1.0)
        check_range("D", self.D, 0.0, math.inf)
        check_range("t_final", self.t_final, 0.0, math.inf, open_low=True)
        check_range("dt0", self.dt0, 0.0, math.inf, open_low=True)
        check_range("dt_growth", self.dt_growth, 1.0, math.inf)
        if self.truncation is not None:
            check_range("truncation", self.truncation, 0.0, math.inf, open_low=True)
        if not isinstance(self.seed, (int, np.integer)) or self.seed < 0:
            raise SettingError("seed", self.seed, "an integer >= 0")
        check_range("omega", self.omega, 0.0, math.inf, open_low=True)
        check_range("fd_length", self.fd_length, 0.0, math.inf, open_low=True)
        check_range("fixed_kernel_time", self.fixed_kernel_time, 0.0, math.inf, open_low=True)
        if self.transfer_method not in TRANSFER_METHODS:
            raise SettingError("transfer_method", self.transfer_method, f"one of {', '.join(TRANSFER_METHODS)}")
        check_range("transfer_tolerance", self.transfer_tolerance, *FGT_TOLERANCE_RANGE)
        if self.method == "fd" and self.kernel == "explicit":
            dx = self.fd_length / self.n
            r = self.D * self.dt0 / dx**2
            if r > 0.5 or self.dt_growth != 1.0:
                raise SettingError(
                    "dt0", self.dt0,
                    f"explicit fd is stable only for r = D dt / dx^2 <= 1/2 with a fixed step: dt0 <= "
                    f"{0.5 * dx**2 / self.D if self.D > 0 else math.inf:.6g} and dt_growth = 1 for n={self.n} "
                    f"(got r = {r:.6g}, dt_growth = {self.dt_growth}); or use kernel implicit",
                )
        if self.scheme not in SCHEMES:
            raise SettingError("scheme", self.scheme, f"one of {', '.join(SCHEMES)}")
        if self.transfer_method in ("taylor", "fgt") and self.truncation is not None:
            raise SettingError("transfer_method", self.transfer_method,
                               "auto or direct when truncation is set (taylor and fgt sum the whole Gaussian)")

    def rng(self) -> np.random.Generator:
        """Generator keyed by (seed, method, N): kernels and eta share positions and walks."""
        key = zlib.crc32(f"{self.method}:{self.n}".encode())
        return np.random.default_rng(np.random.SeedSequence(entropy=self.seed, spawn_key=(key,)))

    def case_columns(self) -> dict:
        """The case parameters written beside every row of a result table."""
        return {
            "method": self.method,
            "kernel": self.kernel,
            "n": int(self.n),
            "eta": float(self.eta),
            "D": float(self.D),
            "truncation": float(self.truncation) if self.truncation is not None else math.inf,
            "dt_growth": float(self.dt_growth),
            "scheme": self.scheme,
            "seed": int(self.seed),
        }


def check_range(name, value, lo, hi, open_low=False):
    """Raise SettingError unless lo <(=) value <= hi and value is a finite number."""
    is_number = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    v = float(value) if is_number else math.nan
    if not math.isfinite(v) or (v <= lo if open_low else v < lo) or v > hi:
        low = f"> {lo}" if open_low else f">= {lo}"
        high = "finite" if hi == math.inf else f"<= {hi}"
        raise SettingError(name, value, f"a number {low} and {high}")
