"""Kernels and sums that the models call: kernel widths, weights and cut-offs (`bandwidths`: Eqs. 17,
20, 23, 26), exact windowed and fast Gauss transforms without an N x N matrix (`gauss`), the
symmetric mass transfer (`mass_transfer`: Eqs. 16-21; several species by one P),
the authors' sequential pairwise loop (`sequential`), the vectorising exp they share (`fastexp`), the
pairs within a cut-off in d dimensions (`neighbours`) and the transfer on them with pair-averaged
tensors (`pair_transfer`, its loops in `pair_kernels`), MTPT's exchange with a uniform tensor and the
2-D kernel estimate of PT in two dimensions (`particles2d`), the particle-killing reaction loop of random-walk
tracking (`reaction_kernels`) and the reactive scenes' reference (`reaction_diffusion`: A, B and C
by Strang splitting on a fine grid, Richardson over three grids). The compiled loops of the
transforms, the transfer and the FD solve are in `gauss_kernels`, `transfer_kernels` and `thomas`,
reached through `compiled.kernels()`: numba's JIT, or the same loops compiled ahead of time for a
simulation job. Imports only from `core`."""
