"""exp(-a) for a >= 0 as inline arithmetic that compilers vectorise (a libm call per pair does
not): the windowed Gauss sums (`gauss`) and the authors' sequential loop (`sequential`) call it
inside their numba loops. Equal to about 1 ulp of exp; bit-identical across both callers."""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

# exp(-a) for the windowed sums, 0 <= a: inline arithmetic that compilers vectorise (a libm
# call per pair does not). e^r by a degree-13 Taylor polynomial on |r| <= ln(2) / 2 (truncation
# < 5e-18 relative), ln 2 split in two for exact reduction, then times 2^-k built from its bits
# (a table lookup vectorises into gathers, which are slow on virtual machines).
_LN2_HI = 0.693147180369123816490  # 32 significant bits: k * _LN2_HI is exact
_LN2_LO = 1.90821492927058770002e-10
_INV_LN2 = 1.4426950408889634
_EXP_MAX_K = 1100.0  # beyond this exp(-a) is 0 in double precision
_EXP_MAX_A = 800.0  # exp(-a) is 0 for a > 745.2; clamped first so that k fits any integer type
_POW2_ZERO_K = 1075  # 2^-k rounds to 0.0 from here on (2^-1074 is the least subnormal)
EXP_NEAR_MAX = 700.0  # exp_neg_near's range: k <= 1010, so 2^-k is normal
_SCALE_K = 1000  # 2^-k as 2^-min(k, 1000) 2^-(k - min(k, 1000)): both factors are normal numbers


@intrinsic
def _f64_from_bits(typingctx, bits):
    """The float64 whose IEEE-754 bit pattern is the int64 ``bits`` (a reinterpretation)."""
    if not isinstance(bits, types.Integer):
        return None

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())

    return types.float64(types.int64), codegen


@intrinsic
def wide_vectors(typingctx):
    """Let LLVM vectorise the calling function's loops with 512-bit vectors (AVX-512), where it
    would stop at 256 bits on CPUs that have them (its default "prefer-vector-width" there): each
    lane computes the same, but a sum the function lets LLVM reorder (fastmath reassoc) may round
    differently. A no-op where the function attribute cannot be set (checked with llvmlite 0.50)."""

    def codegen(context, builder, signature, args):
        try:  # llvmlite accepts only its list of attribute names; LLVM takes this one as a string
            set.add(builder.function.attributes, '"prefer-vector-width"="512"')
        except Exception:  # pragma: no cover - another llvmlite
            pass
        return context.get_dummy_value()

    return types.none(), codegen


@njit(cache=True, inline="always")
def pow2_neg(k):
    """2^-k for an integer-valued float 0 <= k <= 1100, as two factors whose product with a p in
    [0.5, 2] rounds once, as p 2^-k does (0.0 from k = 1075 on, where 2^-k rounds to zero)."""
    k1 = min(k, _SCALE_K)
    hi = _f64_from_bits(np.int64(1023 - np.int32(k1)) << np.int64(52))
    lo_bits = np.int64(1023 - np.int32(k - k1)) << np.int64(52)
    lo = _f64_from_bits(lo_bits if k < _POW2_ZERO_K else np.int64(0))  # bits 0: +0.0
    return hi, lo


@njit(cache=True, inline="always")
def exp_neg(a):
    """exp(-a) for a >= 0, to about 1 ulp."""
    k = min(np.floor(min(a, _EXP_MAX_A) * _INV_LN2 + 0.5), _EXP_MAX_K)  # a float: no int64 lanes
    r = (k * _LN2_HI - a) + k * _LN2_LO  # -a + k ln 2, |r| <= ln(2) / 2
    hi, lo = pow2_neg(k)
    return (_taylor_exp13(r) * hi) * lo  # p 2^-k1 is exact, so one rounding in all


@njit(cache=True, inline="always")
def exp_neg_near(a):
    """exp(-a) for 0 <= a <= EXP_NEAR_MAX, equal to exp_neg bit for bit and cheaper: 2^-k is one
    normal number there."""
    k = np.floor(a * _INV_LN2 + 0.5)
    r = (k * _LN2_HI - a) + k * _LN2_LO
    return _taylor_exp13(r) * _f64_from_bits(np.int64(1023 - np.int32(k)) << np.int64(52))


@njit(cache=True, inline="always")
def _taylor_exp13(r):
    """sum_(n <= 13) r^n / n! (Horner, literal coefficients so the loop vectorises)."""
    return (
        (
            (
                (
                    (
                        (
                            (
                                (
                                    (
                                        (
                                            (
                                                ((1.6059043836821613e-10) * r + 2.08767569878681e-09) * r
                                                + 2.505210838544172e-08
                                            )
                                            * r
                                            + 2.755731922398589e-07
                                        )
                                        * r
                                        + 2.7557319223985893e-06
                                    )
                                    * r
                                    + 2.48015873015873e-05
                                )
                                * r
                                + 0.0001984126984126984
                            )
                            * r
                            + 0.001388888888888889
                        )
                        * r
                        + 0.008333333333333333
                    )
                    * r
                    + 0.041666666666666664
                )
                * r
                + 0.16666666666666666
            )
            * r
            + 0.5
        )
        * r
        + 1.0
    ) * r + 1.0
