"""One simulation's settings (a Case plus physics and numerics), their defaults and checks."""

from __future__ import annotations

import math
import zlib
from dataclasses import asdict, dataclass

import numpy as np

from .case import Case, SettingError, check_range
from .registry import DEFAULT_KERNEL, FGT_TOLERANCE_RANGE, PAPER, TIME_GRIDS, TRANSFER_METHODS
from .timegrid import MAX_STEPS, max_first_step, step_count

MAX_SEED = 2**63 - 1  # seeds are int64 columns of every table


def first_step(method: str, dt_growth: float, dt0: float, fd_dt: float, fixed_dt: float) -> float:
    """The first time step: FD its fixed fd_dt; particles dt0, or fixed_dt when the step is fixed."""
    if method == "fd":
        return fd_dt
    return fixed_dt if dt_growth == 1.0 else dt0


@dataclass(frozen=True)
class RunConfig:
    method: str = "mtpt"
    kernel: str | None = None
    n: int = 300
    eta: float = 1.0
    D: float = PAPER["D"]
    t_final: float = PAPER["t_final"]
    dt0: float | None = None  # None: first_step() with the paper's dt0, fd_dt, fixed_dt
    dt_growth: float | None = None  # None: 1.05 for particles, 1 (fixed) for FD
    truncation: float | None = None  # None: whole Gaussian; else kernel widths
    seed: int = 0
    omega: float = PAPER["omega"]
    fd_length: float = PAPER["fd_length"]
    fixed_kernel_time: float = PAPER["fixed_kernel_time"]
    transfer_method: str = PAPER["transfer_method"]
    transfer_tolerance: float = PAPER["transfer_tolerance"]  # FGT error <= this x sum of |weights| in reach
    scheme: str = PAPER["scheme"]  # registry.SCHEMES: symmetric (Eqs. 16-21), sequential (the authors' loop), ...
    time_grid: str = PAPER["time_grid"]  # exact (last step ends at t_final) or authors (whole steps past it)

    @classmethod
    def for_case(cls, case: Case, **settings) -> RunConfig:
        """The run of ``case`` (which must have an N) with physics and numerics ``settings``."""
        return cls(
            method=case.method,
            kernel=case.kernel,
            n=case.n,
            eta=case.eta,
            truncation=case.truncation,
            dt_growth=case.dt_growth,
            scheme=case.scheme,
            **settings,
        )

    @property
    def case(self) -> Case:
        """The case this run simulates (call on a resolved config)."""
        return Case(self.method, self.kernel, self.n, self.eta, self.truncation, self.dt_growth, self.scheme)

    def resolved(self) -> RunConfig:
        """Fill method-dependent defaults and check every setting."""
        kernel = self.kernel if self.kernel is not None else DEFAULT_KERNEL.get(self.method)
        fd = self.method == "fd"
        growth = self.dt_growth if self.dt_growth is not None else (1.0 if fd else PAPER["dt_growth"])
        dt0 = (
            self.dt0
            if self.dt0 is not None
            else first_step(self.method, growth, PAPER["dt0"], PAPER["fd_dt"], PAPER["fixed_dt"])
        )
        cfg = RunConfig(**{**asdict(self), "kernel": kernel, "dt0": dt0, "dt_growth": growth})
        cfg.check()
        return cfg

    def check(self) -> None:
        # the case dimensions (method, kernel, eta, truncation, dt_growth, scheme, neutral values of
        # those that do not apply to the method) are checked by Case; the rest here
        self.case  # noqa: B018
        if not isinstance(self.n, (int, np.integer)) or self.n < 1:
            raise SettingError("n", self.n, "an integer >= 1")
        if self.method == "fd" and (self.n < 2 or self.n % 2):
            raise SettingError("n", self.n, "for fd an even number of intervals >= 2, so that a node sits at x = 0")
        check_range("D", self.D, 0.0, math.inf)
        check_range("t_final", self.t_final, 0.0, math.inf, open_low=True)
        check_range("dt0", self.dt0, 0.0, math.inf, open_low=True)
        if not isinstance(self.seed, (int, np.integer)) or not 0 <= self.seed <= MAX_SEED:
            raise SettingError(
                "seed", self.seed, f"an integer in [0, 2^63 - 1 = {MAX_SEED}] (tables store it as int64)"
            )
        check_range("omega", self.omega, 0.0, math.inf, open_low=True)
        check_range("fd_length", self.fd_length, 0.0, math.inf, open_low=True)
        check_range("fixed_kernel_time", self.fixed_kernel_time, 0.0, math.inf, open_low=True)
        steps = step_count(self.t_final, self.dt0, self.dt_growth)
        if steps > MAX_STEPS:
            raise SettingError(
                "dt0",
                self.dt0,
                f"a first step reaching t_final = {self.t_final:g} in at most {MAX_STEPS:,} steps with dt_growth = "
                f"{self.dt_growth:g}: >= {max_first_step(self.t_final, self.dt_growth):.3g} (this one needs {steps:,})",
            )
        if self.time_grid not in TIME_GRIDS:
            raise SettingError("time_grid", self.time_grid, f"one of {', '.join(TIME_GRIDS)}")
        if self.transfer_method not in TRANSFER_METHODS:
            raise SettingError("transfer_method", self.transfer_method, f"one of {', '.join(TRANSFER_METHODS)}")
        check_range("transfer_tolerance", self.transfer_tolerance, *FGT_TOLERANCE_RANGE)
        if self.method == "fd" and self.kernel == "explicit":
            dx = self.fd_length / self.n
            r = self.D * self.dt0 / dx**2
            if r > 0.5 or self.dt_growth != 1.0:
                raise SettingError(
                    "dt0",
                    self.dt0,
                    f"explicit fd is stable only for r = D dt / dx^2 <= 1/2 with a fixed step: dt0 <= "
                    f"{0.5 * dx**2 / self.D if self.D > 0 else math.inf:.6g} and dt_growth = 1 for n={self.n} "
                    f"(got r = {r:.6g}, dt_growth = {self.dt_growth}); or use kernel implicit",
                )
        if self.transfer_method in ("taylor", "fgt") and self.truncation is not None:
            raise SettingError(
                "transfer_method",
                self.transfer_method,
                "auto or direct when truncation is set (taylor and fgt sum the whole Gaussian)",
            )

    def rng(self, stream: int = 0) -> np.random.Generator:
        """Generator keyed by (seed, method, N): kernels, eta and schemes share positions and walks.
        Stream 1 feeds the sequential loop's partner orders, so that they leave the walks alone."""
        key = zlib.crc32(f"{self.method}:{self.n}".encode())
        spawn_key = (key,) if stream == 0 else (key, stream)
        return np.random.default_rng(np.random.SeedSequence(entropy=self.seed, spawn_key=spawn_key))

    def case_columns(self) -> dict:
        """The case parameters written beside every row of a result table."""
        return {**self.case.columns(), "D": float(self.D), "seed": int(self.seed), "time_grid": self.time_grid}
