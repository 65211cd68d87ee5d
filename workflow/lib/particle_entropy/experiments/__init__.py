"""Controlled studies beside the 1-D sweeps: the noise floors of the mechanism figure on a lattice
(`lattice`) and Fig. 8's boundary experiment (`fd_domain`). Imports from `core`, `numerics` and
`models`."""
