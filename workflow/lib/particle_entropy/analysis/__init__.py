"""From run tables to findings: ensemble means, standard errors and COMIC tables and minima
(`aggregate`), the bootstrap over realisations and the NaN-safe argmin they share (`resampling`),
the paper's claims judged three ways (`judging`, `claims`) and the adaptive search for COMIC optima
(`optimum`). Imports only from `core`."""
