"""The models: three ways of simulating 1-D diffusion, one module each (random-walk particle
tracking `pt`, mass-transfer particle tracking `mtpt`, finite differences `fd`, and `fd_reactive`,
which carries a reaction on its grid), the random-walk step every particle model takes, in d
dimensions (`walk`), `simulate`, which runs a `RunConfig` step by step into a
table, and the 2-D shear flow of Appendix B (`shear2d`). Imports from `core` and `numerics`."""
