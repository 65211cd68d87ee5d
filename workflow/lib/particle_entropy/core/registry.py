"""The one registry of methods, kernels and schemes, and the one table of the paper's defaults.

Wildcard constraints (workflow/rules/common.smk), CLI choices (cli.py) and the config schema's
enums (a test holds them equal) all come from here; config.yaml holds the same defaults.
"""

from __future__ import annotations

from dataclasses import dataclass

METHODS = ("pt", "mtpt", "fd")
KERNELS = {
    "pt": ("bins", "fixed", "adaptive"),  # reconstruction of the density from particles
    "mtpt": ("collision", "sph"),  # transfer kernel (Eq. 17 / Eqs. 20, 21, 26)
    "fd": ("implicit", "explicit"),  # time scheme of the finite differences
}
ALL_KERNELS = tuple(k for m in METHODS for k in KERNELS[m])
DEFAULT_KERNEL = {m: KERNELS[m][0] for m in METHODS}  # bins, collision, implicit


@dataclass(frozen=True)
class Scheme:
    """How MTPT transfers mass: the flags the step reads (models/mtpt.py) and what they mean.

    ``sequential``: the authors' pairwise loop (numerics/sequential.py), else the symmetric
    transfer matrix of Eqs. 16-21; the loop's details ``by_label`` (visit particles in storage
    order, else left to right with partners to the right), ``symnorm`` (pair weight
    (1/r_i + 1/r_j)/2 of Eq. 18, else the authors' 1/r_i) and ``clip`` (set negative masses to 0);
    ``compensated``: widen a truncated kernel to the whole Gaussian's variance (needs a
    truncation). Legend text lives in core/labels.py, outside what a simulation hashes.
    """

    name: str
    description: str
    sequential: bool = False
    by_label: bool = True
    symnorm: bool = False
    clip: bool = True
    compensated: bool = False


# The first two are the paper's equations and the authors' code; each later one changes one
# detail, for the controlled experiments of Fig. 9 (sequential.py states the loop fact by fact).
SCHEME_RECORDS = {
    s.name: s
    for s in (
        Scheme("symmetric", "the symmetric transfer matrix of Eqs. 16-21"),
        Scheme("sequential", "the authors' sequential pairwise loop", sequential=True),
        Scheme(
            "compensated",
            "Eqs. 16-21 with the truncated kernel widened to keep the whole Gaussian's variance",
            compensated=True,
        ),
        Scheme(
            "sequential_sorted",
            "the authors' loop visiting particles left to right, partners to the right",
            sequential=True,
            by_label=False,
        ),
        Scheme(
            "sequential_symnorm",
            "the authors' loop with the pair weight W_ij (1/r_i + 1/r_j)/2 of Eq. 18",
            sequential=True,
            symnorm=True,
        ),
        Scheme("sequential_noclip", "the authors' loop without clipping negative masses", sequential=True, clip=False),
    )
}
SCHEMES = tuple(SCHEME_RECORDS)
SCHEME_DOCS = {name: s.description for name, s in SCHEME_RECORDS.items()}
TIME_GRIDS = ("exact", "authors")  # last step shortened to end at t_final, or whole steps while t < t_final
TRANSFER_METHODS = ("auto", "direct", "fgt", "taylor")
SHEAR_CASES = ("rw_nodrift", "rw_drift", "mt")

# The measurement points common to every model (Section 6, "Four important points regarding the
# COMIC", point 1: "15 randomly chosen 'measurement points' common to all simulations"): this many
# points, uniform on the paper's FD domain [-fd_length/2, fd_length/2], drawn once from
# numpy.random.default_rng(MEASUREMENT_SEED) and sorted (measures.measurement_points). The same
# for every case and every seed; the SSE_points and COMIC_points columns are taken at them.
MEASUREMENT_POINTS = 15
MEASUREMENT_SEED = 20200615  # fixed: changing it changes every SSE_points and COMIC_points

FGT_TOLERANCE = 1e-17  # fast Gauss transform error / summed |weights| in reach: round-off
FGT_TOLERANCE_RANGE = (1e-30, 0.1)

# The paper's settings (../shared/docs/experiments.md beside the repository); config.yaml and
# the schema's defaults equal these.
PAPER = {
    "D": 1e-3,  # diffusion coefficient [L^2/T]
    "t_final": 1000.0,  # [T]
    "omega": 10.0,  # particle domain length, positions on [-omega/2, omega/2] [L]
    "fd_length": 12.0,  # FD domain [-6, 6] [L]
    "fixed_kernel_time": 1.0,  # fixed PT kernel has variance 2 D x this time [T]
    "dt0": 0.01,  # first particle step [T]
    "fd_dt": 0.05,  # FD fixed step [T]
    "fixed_dt": 1.0,  # particle step when dt_growth = 1 [T]
    "eta": 1.0,  # fraction of D by mass transfer
    "truncation": None,  # None: whole Gaussian; else kernel widths (3 = authors' code)
    "dt_growth": 1.05,  # dt_{n+1} = growth * dt_n
    "scheme": "symmetric",
    "time_grid": "exact",
    "transfer_method": "auto",
    "transfer_tolerance": FGT_TOLERANCE,
    "shear_beta": 0.5,  # Appendix B mass-transfer coefficient (Eq. 16)
}
