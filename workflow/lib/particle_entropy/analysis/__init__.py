"""From run tables to findings: ensemble means, standard errors and bootstrap COMIC minima
(`aggregate`), the paper's claims judged (`claims`) and the adaptive search for COMIC optima
(`optimum`). Imports only from `core`."""
