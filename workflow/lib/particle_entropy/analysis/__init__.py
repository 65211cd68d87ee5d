"""From run tables to findings: ensemble means, standard errors and COMIC tables and minima
(`aggregate`), the bootstrap over realisations and the NaN-safe argmin they share (`resampling`),
the paper's claims judged three ways (`judging`, `claims`), and the adaptive-search engine (`search`:
rounds, plans, seed blocks) with its two kinds, the search for COMIC optima (`optimum`) and a
scene's cheapest model (`scene_search`); the late slope of the segregation runs with its interval
over seeds (`segregation`) and a time-step error's observed order with its interval (`step_error`).
Imports only from `core` (and `scene_search` from `experiments`)."""
