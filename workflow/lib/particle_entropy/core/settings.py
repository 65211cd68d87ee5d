"""The one typed definition of every run setting: config key, CLI option, default, range, meaning.

From ``SETTINGS`` come the paper's defaults (``PAPER``), ``RunConfig``'s defaults and range
checks, the CLI's options (cli.py) and the schema's entries for these keys, which
``python -m particle_entropy.pipeline.schemagen --write`` writes into
workflow/schemas/config.schema.yaml (tests/test_settings.py fails when the file is stale).
Settings that are case dimensions (eta, truncation, dt_growth, scheme) live under
``case_defaults`` in a config and are checked by ``Case``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .registry import FGT_TOLERANCE, FGT_TOLERANCE_RANGE, SCHEMES, TIME_GRIDS, TRANSFER_METHODS


@dataclass(frozen=True)
class Setting:
    """One setting: ``name`` is its RunConfig field (CLI option ``--name`` with dashes), ``key``
    its config key. Numbers lie in [low, high] (``open_low``: low excluded); ``choices`` lists
    the allowed words; ``none`` allows the word none (None), as truncation does."""

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

    @property
    def section(self) -> str:
        return self.key.split(".")[0]

    @property
    def option(self) -> str:
        return "--" + self.name.replace("_", "-")

    def allowed(self) -> str:
        """The allowed values in words, as error messages and help texts give them."""
        if self.choices is not None:
            return "one of " + ", ".join(self.choices)
        if self.high != math.inf:
            words = f"a number in {'(' if self.open_low else '['}{self.low:g}, {self.high:g}]"
        else:
            words = f"a number {'>' if self.open_low else '>='} {self.low:g}"
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
        "(1e-17 = round-off: mass conserved to 1e-13)",
        low=FGT_TOLERANCE_RANGE[0],
        high=FGT_TOLERANCE_RANGE[1],
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
        1.05,
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
PAPER = {s.name: s.default for s in SETTINGS} | {"shear_beta": 0.5}  # Appendix B coefficient (Eq. 16)
