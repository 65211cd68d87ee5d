"""Kernels and sums that the models call: kernel widths and weights (Eqs. 17, 20, 23, 26), exact
windowed and fast Gauss transforms without an N x N matrix (`gauss`), the vectorising exp that
they and the authors' loop share (`fastexp`), the symmetric mass transfer (Eqs. 16-21), the
authors' sequential pairwise loop (`sequential`) and the shear flow's pair kernels
(`shear_kernels`). Imports only from `core`."""
