"""What every part shares: the registry of methods, kernels and schemes, the one definition of
the run settings, the `Case` value, its legend text and the checked `RunConfig`, the time grids,
the one cost model of a run (`runcost`: counted step work, or a tabulated log-log curve),
the measures of mixing and error (Eqs. 2-14, 43-44), the reaction kinds and their closed-form
kinetics (`reactions`), the source kinds and exact plumes in 1-D (`sources`, `reference`) and in 2-D
(`sources2d`, `reference2d`), a continuous release (`release`) and its plume's moments (`released`),
a reactive reference's file (`reference_file`), per-step records,
Parquet input and output
and the allocator setting of simulation processes. Imports nothing from the other subpackages."""
