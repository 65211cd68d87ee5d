"""The three ways of simulating 1-D diffusion, one module each (random-walk particle tracking
`pt`, mass-transfer particle tracking `mtpt`, finite differences `fd`), and `simulate`, which
runs a `RunConfig` step by step into a table. Imports from `core` and `numerics`."""
