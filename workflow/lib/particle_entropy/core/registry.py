"""The one registry of methods, kernels and schemes, and the one table of the paper's defaults.

Wildcard constraints (workflow/rules/common.smk), CLI choices (cli.py) and the config schema's
enums (a test holds them equal) all come from here; config.yaml holds the same defaults.
"""

from __future__ import annotations

METHODS = ("pt", "mtpt", "fd")
KERNELS = {
    "pt": ("bins", "fixed", "adaptive"),  # reconstruction of the density from particles
    "mtpt": ("collision", "sph"),  # transfer kernel (Eq. 17 / Eqs. 20, 21, 26)
    "fd": ("implicit", "explicit"),  # time scheme of the finite differences
}
ALL_KERNELS = tuple(k for m in METHODS for k in KERNELS[m])
DEFAULT_KERNEL = {m: KERNELS[m][0] for m in METHODS}  # bins, collision, implicit
# How the mass transfer is computed (sequential.py states the authors' loop fact by fact). The
# variants after the first two change one detail each, for the controlled experiments of Fig. 9.
SCHEME_DOCS = {
    "symmetric": "the symmetric transfer matrix of Eqs. 16-21",
    "sequential": "the authors' sequential pairwise loop",
    "compensated": "Eqs. 16-21 with the truncated kernel widened to keep the whole Gaussian's variance",
    "sequential_sorted": "the authors' loop visiting particles left to right, partners to the right",
    "sequential_symnorm": "the authors' loop with the pair weight W_ij (1/r_i + 1/r_j)/2 of Eq. 18",
    "sequential_noclip": "the authors' loop without clipping negative masses",
}
SCHEMES = tuple(SCHEME_DOCS)
SCHEME_LABELS = {  # legend text of a non-default scheme
    "sequential": "sequential loop",
    "compensated": "compensated width",
    "sequential_sorted": "sequential loop in position order",
    "sequential_symnorm": "sequential loop, symmetric weights",
    "sequential_noclip": "sequential loop, no clipping",
}
TRUNCATED_SCHEMES = ("compensated",)  # schemes that need a truncation
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
