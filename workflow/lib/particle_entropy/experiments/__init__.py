"""Controlled studies beside the 1-D sweeps: the noise floors of the mechanism figure on a lattice
(`lattice`), Fig. 8's boundary experiment (`fd_domain`), and the noise-driven segregation of
A + B -> C by PT and MTPT (`segregation`). Imports from `core`, `numerics` and `models`."""
