"""The figures: the drawing toolkit and the paper's figures (`plots`), the mechanism figure
(`plots_mechanism`), the optimum searches (`plots_optimum`) and the shear flow (`plots_shear`).
Imports from `core`, `numerics`, `experiments` and `analysis`; never from `pipeline`."""
