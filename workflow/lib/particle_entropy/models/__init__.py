"""The models: three ways of simulating 1-D diffusion, one module each (random-walk particle
tracking `pt`, mass-transfer particle tracking `mtpt`, finite differences `fd`), each with one step
that moves every species; the random-walk step every particle model takes, in d dimensions (`walk`);
`reaction_step`, the reaction applied after transport; `release_step`, what a continuous release adds to
each model's step; `simulate`, the one runner of a `RunConfig`
(conservative or reactive) step by step into a table; and the 2-D shear flow of Appendix B
(`shear2d`). Imports from `core` and `numerics`."""
