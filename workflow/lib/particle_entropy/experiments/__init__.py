"""Studies beyond the 1-D sweeps: the 2-D shear flow of Appendix B (`shear2d`), the noise floors of
the mechanism figure on a lattice (`lattice`) and Fig. 8's boundary experiment (`fd_domain`).
Imports from `core`, `numerics` and `models`."""
