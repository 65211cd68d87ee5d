"""The settings a simulation reads: physics, time grid, numerics and case defaults.

These are declared apart from every other config section (core/settings.py gathers them all)
because a simulation job's code hash (pipeline/codeversion.simulation_code) covers the modules it
imports: editing a claims tolerance, a scene's cost constant or a figure option then reruns no
simulation. This module imports nothing but the registry; ``Setting`` is the one declaration form
of every section.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .registry import FGT_TOLERANCE, FGT_TOLERANCE_RANGE, LOOP_ARITHMETICS, SCHEMES, TIME_GRIDS, TRANSFER_METHODS

MAX_SEED = 2**63 - 1  # seeds are int64 columns of every table
NO_DEFAULT = object()  # a setting the config must give (or may leave out, with no default)
DT_GROWTH = 1.05  # the paper's time-step growth dt_{n+1} / dt_n: every particle case's default


@dataclass(frozen=True)
class Setting:
    """One setting: ``name`` is its field (a RunConfig's: CLI option ``--name`` with dashes),
    ``key`` its config key (``<name>`` standing for any key of a mapping, ``[]`` for any item of
    a list). ``kind`` is number, integer, boolean or string (with ``choices``, the allowed
    words), or shape: a structured value whose JSON-schema ``shape`` is given. Numbers lie in
    [low, high] (``open_low``: low excluded); ``none`` allows the word none (None), as truncation
    does; ``range_text`` states a range that depends on other fields; ``required``: the config
    must give it."""

    name: str
    key: str
    default: object
    doc: str
    unit: str = "-"
    low: float | None = None
    high: float = math.inf
    open_low: bool = False
    choices: tuple[str, ...] | None = None
    none: bool = False
    kind: str = "number"
    shape: dict | None = None
    range_text: str | None = None
    required: bool = False

    @property
    def section(self) -> str:
        """The key of the mapping the setting sits in (``physics``, ``mechanism.lattice``; the
        config itself: empty)."""
        return self.key.rsplit(".", 1)[0] if "." in self.key else ""

    @property
    def has_default(self) -> bool:
        return self.default is not NO_DEFAULT

    @property
    def option(self) -> str:
        return "--" + self.name.replace("_", "-")

    def allowed(self) -> str:
        """The allowed values in words, as error messages and help texts give them."""
        if self.range_text is not None:
            return self.range_text
        if self.kind == "shape":
            raise ValueError(f"setting {self.key}: a structured value needs its range_text")
        if self.choices is not None:
            return "one of " + ", ".join(self.choices)
        if self.kind == "boolean":
            return "true or false"
        integer = self.kind == "integer"
        noun, num = ("an integer", lambda v: f"{int(v):,}") if integer else ("a number", lambda v: f"{v:g}")
        if self.high != math.inf:
            words = f"{noun} in {'(' if self.open_low else '['}{num(self.low)}, {num(self.high)}]"
        else:
            words = f"{noun} {'>' if self.open_low else '>='} {num(self.low)}"
        return ("none or " if self.none else "") + words


SETTINGS = (
    Setting("D", "physics.D", 1e-3, "diffusion coefficient", "L^2/T", low=0.0, open_low=True),
    Setting("t_final", "physics.t_final", 1000.0, "final time", "T", low=0.0, open_low=True),
    Setting(
        "omega",
        "physics.omega",
        10.0,
        "particle domain length Omega, particles on [-Omega/2, Omega/2]",
        "L",
        0.0,
        open_low=True,
    ),
    Setting(
        "fd_length",
        "physics.fd_length",
        12.0,
        "finite-difference domain length, centred on x = 0",
        "L",
        0.0,
        open_low=True,
    ),
    Setting(
        "fixed_kernel_time",
        "physics.fixed_kernel_time",
        1.0,
        "fixed-kernel PT reconstructs with a Gaussian of variance 2 D x this time",
        "T",
        0.0,
        open_low=True,
    ),
    Setting(
        "dt0",
        "time.dt0",
        0.01,
        "first particle time step; later steps grow by the case's dt_growth",
        "T",
        0.0,
        open_low=True,
    ),
    Setting("fd_dt", "time.fd_dt", 0.05, "finite-difference fixed time step", "T", 0.0, open_low=True),
    Setting("fixed_dt", "time.fixed_dt", 1.0, "fixed step of particle cases with dt_growth 1", "T", 0.0, open_low=True),
    Setting(
        "transfer_method",
        "numerics.transfer_method",
        "auto",
        "Gauss-transform algorithm of the mass transfer: auto = the exact windowed sum for few neighbours or "
        "truncated kernels, the fast Gauss transform otherwise",
        choices=TRANSFER_METHODS,
    ),
    Setting(
        "transfer_tolerance",
        "numerics.transfer_tolerance",
        FGT_TOLERANCE,
        "fast Gauss transform error bound, relative to the summed |weights| within the cut-off "
        "(the default is round-off: mass conserved to 1e-13)",
        low=FGT_TOLERANCE_RANGE[0],
        high=FGT_TOLERANCE_RANGE[1],
    ),
    Setting(
        "loop_arithmetic",
        "numerics.loop_arithmetic",
        "fused",
        "arithmetic of the authors' sequential loop (mtpt schemes with the loop): fused = each exchange's mass "
        "update one fused multiply-add and the row sums vectorised, equal to exact to round-off in about half its "
        "time (docs/speed.md); exact = bit for bit the loop of tests/sequential_reference.py",
        choices=LOOP_ARITHMETICS,
    ),
    Setting("eta", "case_defaults.eta", 1.0, "fraction of D done by mass transfer (mtpt only)", low=0.0, high=1.0),
    Setting(
        "truncation",
        "case_defaults.truncation",
        None,
        "transfer-kernel truncation (mtpt only): none = the whole Gaussian, else a number of kernel widths "
        "(3 = the authors' code)",
        "kernel widths",
        low=0.0,
        open_low=True,
        none=True,
    ),
    Setting(
        "dt_growth",
        "case_defaults.dt_growth",
        DT_GROWTH,
        "time-step growth factor dt_{n+1} = dt_growth dt_n (1 = fixed step time.fixed_dt; pt and mtpt only; at "
        "most 10: a larger factor reaches t_final in a few steps and overflows at 1e308)",
        low=1.0,
        high=10.0,
    ),
    Setting(
        "scheme",
        "case_defaults.scheme",
        "symmetric",
        "mass-transfer scheme (mtpt only, registry.SCHEME_RECORDS)",
        choices=SCHEMES,
    ),
    Setting(
        "time_grid",
        "case_defaults.time_grid",
        "exact",
        "particle time grid: exact = the last step is shortened to end at t_final; authors = whole growing "
        "steps while t < t_final, as the authors' code (175 steps ending at t = 1021.1 for the paper's "
        "settings; pt and mtpt only); FD steps always end at t_final",
        choices=TIME_GRIDS,
    ),
)
BY_NAME = {s.name: s for s in SETTINGS}
CASE_SETTINGS = tuple(s.name for s in SETTINGS if s.section == "case_defaults")
# The paper's settings (../shared/docs/experiments.md beside the repository); config.yaml equals these.
PAPER = {s.name: s.default for s in SETTINGS}


def defaults(settings) -> dict:
    """Field name -> default of the settings that have one."""
    return {s.name: s.default for s in settings if s.has_default}
