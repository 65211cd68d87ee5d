"""The 2-D shear flow's settings (Appendix B): ShearConfig's fields, declared apart from the other
sections so that the shear job's code hash (models/shear2d.py imports this) follows only them."""

from __future__ import annotations

from .registry import SHEAR_CASES
from .run_settings import MAX_SEED, NO_DEFAULT, Setting

SHEAR_MAX_N = 10**8  # shear particles: 5,000 x the paper's, ~40 GB for a random walk; more is a typo
SHEAR = (  # Appendix B; ShearConfig's fields (models/shear2d.py) besides `case`
    Setting(
        "cases",
        "shear.cases",
        NO_DEFAULT,
        "cases to run: rw_nodrift, rw_drift (random walks without / with the grad.D drift), mt (mass transfer only)",
        kind="shape",
        shape={
            "type": "array",
            "minItems": 1,
            "uniqueItems": True,
            "items": {"type": "string", "enum": list(SHEAR_CASES)},
        },
        range_text="a list of " + ", ".join(SHEAR_CASES) + ", each once",
        required=True,
    ),
    Setting(
        "seed",
        "shear.seed",
        0,
        "random seed",
        kind="integer",
        low=0,
        high=MAX_SEED,
        range_text="an integer in [0, 2^63 - 1] (stored as int64)",
        required=True,
    ),
    Setting(
        "n",
        "shear.n",
        20_000,
        "particles, uniform over the domain (the memory check may refuse fewer)",
        kind="integer",
        low=1,
        high=SHEAR_MAX_N,
        required=True,
    ),
    Setting("length", "shear.length", 400.0, "periodic domain length in x", "L", 0.0, open_low=True, required=True),
    Setting(
        "strip_lo",
        "shear.strip_lo",
        90.0,
        "left edge of the initial strip",
        "L",
        0.0,
        range_text="a number in [0, length]",
        required=True,
    ),
    Setting(
        "strip_hi",
        "shear.strip_hi",
        110.0,
        "right edge of the initial strip",
        "L",
        0.0,
        open_low=True,
        range_text="a number in (strip_lo, length]",
        required=True,
    ),
    Setting(
        "alpha_L",
        "shear.alpha_L",
        1e-2,
        "longitudinal dispersivity",
        "L",
        0.0,
        open_low=True,
        range_text="a number > 0 with a step's dispersion sqrt(2 alpha_L v_max dt) <= length / 10 (v_max = 1/4)",
        required=True,
    ),
    Setting(
        "alpha_T",
        "shear.alpha_T",
        1e-3,
        "transverse dispersivity",
        "L",
        0.0,
        range_text="a number >= 0 with a step's dispersion sqrt(2 alpha_T v_max dt) <= 1/10 of the channel's width "
        "(v_max = 1/4): alpha_T dt <= 0.02",
        required=True,
    ),
    Setting("beta", "shear.beta", 0.5, "mass-transfer coefficient of Eq. 16 for the mt case", low=0.0, high=1.0),
    Setting("dt", "shear.dt", 1.0, "time step", "T", 0.0, open_low=True, required=True),
    Setting(
        "t_final",
        "shear.t_final",
        500.0,
        "final time",
        "T",
        0.0,
        open_low=True,
        range_text="a number > 0, a whole number of steps dt",
        required=True,
    ),
)
